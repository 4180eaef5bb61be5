//! The light-transport algorithms: one closed enum, prepared once per job
//! (photon maps traced, lanes compiled), one file each, answering the same
//! questions — render a pass into the film, show a coarse preview, say what
//! a tile looks like now. What they share is written once: next-event
//! estimation (`next_event`), BSDFs, occlusion and the lanes (`world`).

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
pub mod whitted;

use std::sync::Arc;
use std::time::Duration;

use rayon::prelude::*;

use crate::render::film::{Film, FilmTile, TermSums};
use crate::render::settings::{Method, RenderSettings};
use crate::render::world::camera::{CameraModel, CameraTile, TileRect};
use crate::render::world::rng::PassStreams;
use crate::render::world::World;
use crate::scene::Rgb;
use path_lanes::PathLanes;
use photon_map::maps::resolve_max_radius;
use photon_map::{PhotonMapStats, PhotonMaps, QueryStats};

/// Work counted per tile and summed per pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    pub rays: u64,
    pub non_finite: u64,
    pub queries: QueryStats,
    /// Bidirectional methods: light subpath vertices made, connections
    /// traced (to the camera, to lights, between vertices) and light
    /// vertices merged.
    pub light_vertices: u64,
    pub connections: u64,
    pub merges: u64,
}

impl Counters {
    pub fn add(&mut self, other: &Counters) {
        self.rays += other.rays;
        self.non_finite += other.non_finite;
        self.queries.add(&other.queries);
        self.light_vertices += other.light_vertices;
        self.connections += other.connections;
        self.merges += other.merges;
    }
}

/// Photon work of one pass (photon mapping's queries, SPPM's photons).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonPassStats {
    /// k-NN queries made while rendering the pass.
    pub queries: QueryStats,
    /// SPPM: photons traced and stored this pass, and where its time went.
    pub photons_traced: u64,
    pub photons_stored: u64,
    pub times: SppmTimes,
    /// SPPM: mean gather radius over pixels after the pass.
    pub mean_radius: f32,
}

/// Where an SPPM pass's time went, stage by stage (wall-clock, each stage
/// on every worker).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SppmTimes {
    /// Camera rays to each pixel's visible point, with its direct light.
    pub eye: Duration,
    /// Emitting and tracing the pass's photons.
    pub trace: Duration,
    /// The hash grid over the stored photons (`photon_map::grid`).
    pub build: Duration,
    /// Every visible point's photons gathered, its radius and flux updated.
    pub gather: Duration,
}

impl SppmTimes {
    /// The stages, named, in the order a pass runs them.
    pub fn stages(&self) -> [(&'static str, Duration); 4] {
        [("eye pass", self.eye), ("photon tracing", self.trace), ("photon grid", self.build), ("gather", self.gather)]
    }

    /// "eye pass 95 ms, photon tracing 364 ms, …": three decimals for a
    /// stage under 10 ms (a small render's are microseconds).
    pub fn summary(&self) -> String {
        let stages: Vec<String> = self
            .stages()
            .iter()
            .map(|(stage, time)| {
                let ms = time.as_secs_f64() * 1e3;
                format!("{stage} {ms:.*} ms", if ms < 10.0 { 3 } else { 0 })
            })
            .collect();
        stages.join(", ")
    }
}

/// What one pass did.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassReport {
    pub counters: Counters,
    pub photon: PhotonPassStats,
    pub paths: bidir::PathPassStats,
    /// The terms of the estimate's own relMSE, where the film keeps halves.
    pub noise: TermSums,
}

/// Bounces before Russian roulette may end a path (the scalar tracer and
/// the lanes alike).
pub(crate) const ROULETTE_DEPTH: u32 = 3;

/// Everything a pass reads: shared, immutable, built once per job.
pub struct Stage<'a> {
    pub world: &'a World,
    pub camera: &'a CameraModel,
    pub settings: &'a RenderSettings,
    /// The world compiled for eight rays at a time, where the CPU and the
    /// world allow: every algorithm traces through it.
    pub lanes: Option<&'a PathLanes>,
}

impl Stage<'_> {
    /// The streams of sample `sample` of every pixel.
    pub fn streams(&self, sample: u64) -> PassStreams {
        PassStreams::new(sample, self.settings.seed)
    }

    /// A sample as it may enter the film: finite, not negative, clamped only
    /// if asked; a NaN or infinity is counted and dropped.
    #[inline]
    pub fn accept(&self, value: Rgb, counters: &mut Counters) -> Option<Rgb> {
        if !value.is_finite() {
            counters.non_finite += 1;
            return None;
        }
        let value = value.max(Rgb::ZERO);
        let clamp = self.settings.firefly_clamp;
        Some(if clamp > 0.0 { value.min(Rgb::splat(clamp)) } else { value })
    }
}

/// What a pass tells its driver, and asks it.
pub trait PassObserver: Sync {
    /// Whether the job is still wanted: checked before every tile and every
    /// chunk of photons, so a restart never waits for a pass to end.
    fn is_current(&self) -> bool;
    /// Whether the driver wants each tile's estimate after each pass.
    fn wants_tiles(&self) -> bool;
    /// Whether it wants each pixel's estimated variance with it.
    fn wants_variance(&self) -> bool;
    /// Whether it wants the film's own relMSE estimate after pass `pass`
    /// (counted from 0).
    fn wants_noise(&self, pass: u32) -> bool;
    fn tile(&self, rect: TileRect, pixels: Vec<[f32; 3]>, variance: Option<Vec<[f32; 3]>>);
    /// Whether it shows what each strategy of a bidirectional method brings.
    fn wants_strategies(&self) -> bool {
        false
    }
    /// Every strategy's images so far (when it wants them).
    fn strategies(&self, _images: bidir::strategies::StrategyImages) {}
}

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
            Method::Whitted => Integrator::Whitted(whitted::Whitted::new(settings.max_depth.max(1))),
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
