//! The light-transport algorithms: one closed enum, prepared once per job
//! (photon maps traced), one file each, answering the same questions —
//! render a pass into the film, show a coarse preview, say what a tile
//! looks like now. Here the dispatch; in `vocabulary` what every pass
//! reads, counts and reports. What they share is written once: next-event
//! estimation (`next_event`), BSDFs, occlusion and the lanes (`world`,
//! `world::lane_world`, compiled once per job and read through `Stage::lanes`).

pub mod bidir;
pub mod flying;
pub mod next_event;
pub mod path;
pub mod path_lanes;
pub mod photon;
pub mod photon_map;
pub mod reorder;
pub mod shadow_batch;
pub mod specular;
pub mod sppm;
mod vocabulary;
pub mod whitted;

use std::sync::Arc;

use rayon::prelude::*;

use crate::render::film::{Film, FilmTile, TermSums};
use crate::render::settings::Method;
use crate::render::world::camera::{CameraTile, TileRect};
use crate::render::world::rng::PassStreams;
use crate::scene::Rgb;
use photon_map::maps::resolve_max_radius;
use photon_map::{PhotonMapStats, PhotonMaps};

pub(crate) use vocabulary::ROULETTE_DEPTH;
pub use vocabulary::{Counters, PassObserver, PassReport, PhotonPassStats, SppmTimes, Stage};

/// Sample index used for the coarse preview, outside any real pass's range.
const PREVIEW_SAMPLE: u64 = u64::MAX;
const PREVIEW_BLOCK: u32 = 8;

pub enum Integrator {
    Whitted(whitted::Whitted),
    Path(path::PathTracer),
    Photon(photon::PhotonMapping),
    Sppm(sppm::Sppm),
    /// Light tracing, BDPT, bidirectional photon mapping and VCM.
    Bidir(bidir::Bidir),
}

impl Integrator {
    /// The algorithm of `stage.settings`, prepared: `maps` are photon maps
    /// made earlier for this scene and settings (traced afresh when absent).
    /// None if the job was abandoned while preparing.
    pub fn prepare(
        stage: &Stage,
        film: &Film,
        visible_radius: f32,
        maps: Option<Arc<PhotonMaps>>,
        observer: &dyn PassObserver,
    ) -> Option<Self> {
        let settings = stage.settings;
        Some(match &settings.method {
            Method::Whitted => Integrator::Whitted(whitted::Whitted::new(settings.max_depth)),
            Method::Path => Integrator::Path(path::PathTracer::new(settings.max_depth)),
            Method::Photon(photon) => {
                let maps = match maps {
                    Some(maps) => maps,
                    None => Arc::new(PhotonMaps::build_until(
                        stage.world,
                        stage.lanes,
                        photon,
                        settings.seed,
                        settings.max_depth,
                        &|| observer.is_current(),
                    )?),
                };
                let max_radius = resolve_max_radius(visible_radius, photon);
                Integrator::Photon(photon::PhotonMapping::new(maps, photon, settings.max_depth, max_radius))
            }
            Method::Sppm(sppm) => Integrator::Sppm(sppm::Sppm::new(film, sppm, settings, visible_radius)),
            Method::LightTracing | Method::Bdpt(_) | Method::Bpm(_) | Method::Vcm(_) => {
                Integrator::Bidir(bidir::Bidir::new(stage.world, settings, visible_radius))
            }
        })
    }

    /// The photon maps' statistics, for photon mapping.
    pub fn photon_maps(&self) -> Option<PhotonMapStats> {
        match self {
            Integrator::Photon(p) => Some(p.maps.stats),
            _ => None,
        }
    }

    /// Render pass `pass` into `film`. None if the job was abandoned.
    pub fn pass(
        &mut self,
        stage: &Stage,
        film: &mut Film,
        pass: u32,
        observer: &dyn PassObserver,
    ) -> Option<PassReport> {
        match self {
            Integrator::Sppm(sppm) => sppm.pass(stage, film, pass, observer),
            Integrator::Bidir(bidir) => bidir.pass(stage, film, pass, observer),
            _ => self.sample_pass(stage, film, pass, observer),
        }
    }

    /// What tile `tile` of `film` shows now.
    pub fn tile_pixels(&self, film: &Film, tile: usize) -> Vec<[f32; 3]> {
        match self {
            Integrator::Sppm(sppm) => sppm.tile_pixels(film, tile),
            _ => film.tiles[tile].mean(),
        }
    }

    /// One pass of independent samples per pixel: every tile in parallel,
    /// each sample accepted (`Stage::accept`) and added to its pixel.
    fn sample_pass(
        &self,
        stage: &Stage,
        film: &mut Film,
        pass: u32,
        observer: &dyn PassObserver,
    ) -> Option<PassReport> {
        let streams = stage.streams(pass as u64);
        let per_tile: Vec<(Counters, TermSums)> = film
            .tiles
            .par_iter_mut()
            // one tile a task: rayon's default leaves are a quarter of the
            // tiles at two threads, and the thread left with the costly
            // quarter finishes the pass alone
            .with_max_len(1)
            .map(|tile| {
                let mut counters = Counters::default();
                if !observer.is_current() {
                    return (counters, TermSums::default());
                }
                self.render_tile(stage, tile, streams, &mut counters);
                if observer.wants_tiles() {
                    let variance = if observer.wants_variance() { tile.variance() } else { None };
                    observer.tile(tile.rect, tile.mean(), variance);
                }
                let noise = if observer.wants_noise(pass) { tile.noise_terms() } else { TermSums::default() };
                (counters, noise)
            })
            .collect();
        if !observer.is_current() {
            return None;
        }
        let mut report = PassReport::default();
        for (counters, noise) in &per_tile {
            report.counters.add(counters);
            report.noise.add(noise);
        }
        report.photon.queries = report.counters.queries;
        Some(report)
    }

    fn render_tile(&self, stage: &Stage, tile: &mut FilmTile, streams: PassStreams, counters: &mut Counters) {
        let camera_tile = CameraTile { camera: stage.camera, rect: tile.rect, streams };
        let mut rejected = Counters::default();
        let mut pass = tile.pass_sums();
        // Each sample accepted and added as the integrator hands it out
        let mut add = |i: usize, value: Rgb| pass.add(i, stage.accept(value, &mut rejected).unwrap_or(Rgb::ZERO));
        match self {
            Integrator::Whitted(whitted) => whitted.render_tile(stage, &camera_tile, &mut add, counters),
            Integrator::Path(path) => path.render_tile(stage, &camera_tile, &mut add, counters),
            Integrator::Photon(photon) => photon.render_tile(stage, &camera_tile, &mut add, counters),
            Integrator::Sppm(_) | Integrator::Bidir(_) => unreachable!("they render their own passes"),
        }
        counters.add(&rejected);
        tile.samples += 1;
    }

    /// One sample per block of `rect`, copied over the block: something to
    /// show before the first pass.
    pub fn preview_tile(&self, stage: &Stage, rect: TileRect) -> Vec<[f32; 3]> {
        let mut pixels = vec![[0.0; 3]; rect.pixels()];
        let mut counters = Counters::default();
        let streams = stage.streams(PREVIEW_SAMPLE);
        let mut scratch = None;
        for by in (0..rect.height).step_by(PREVIEW_BLOCK as usize) {
            for bx in (0..rect.width).step_by(PREVIEW_BLOCK as usize) {
                let (w, h) = (PREVIEW_BLOCK.min(rect.width - bx), PREVIEW_BLOCK.min(rect.height - by));
                let (x, y) = (rect.x + bx + w / 2, rect.y + by + h / 2);
                let (ray, mut sampler) = stage.camera.sample_ray(x, y, streams);
                let sampler = &mut sampler;
                let value = match self {
                    Integrator::Whitted(whitted) => whitted.radiance(stage.world, &ray, sampler, &mut counters),
                    Integrator::Path(path) => path.radiance(stage.world, &ray, sampler, &mut counters),
                    Integrator::Photon(photon) => {
                        let scratch = scratch.get_or_insert_with(|| photon.scratch());
                        photon.radiance(stage.world, &ray, sampler, &mut counters, scratch)
                    }
                    // SPPM has no estimate before its first pass: show direct light
                    Integrator::Sppm(sppm) => sppm.direct(stage.world, &ray, sampler, &mut counters),
                    // A bidirectional pass has no tile of its own: a path-traced one
                    Integrator::Bidir(_) => {
                        path::radiance(stage.world, &ray, stage.settings.max_depth, sampler, &mut counters)
                    }
                };
                let value = stage.accept(value, &mut counters).unwrap_or(Rgb::ZERO);
                for y in by..by + h {
                    for x in bx..bx + w {
                        pixels[(y * rect.width + x) as usize] = value.to_array();
                    }
                }
            }
        }
        pixels
    }
}
