//! Light tracing, bidirectional path tracing, bidirectional photon mapping
//! and vertex connection and merging: one engine (after SmallVCM, Georgiev
//! et al. 2012), four sets of strategies. Each pass traces one light
//! subpath per pixel, keeps its non-specular vertices (and, to merge, a
//! hash grid of them, `merging::MergeGrid`), joins them to the camera, then
//! traces one camera subpath per pixel that samples lights, connects to its
//! pixel's light subpath and merges with the light vertices around it.
//!
//! - Light tracing: only the light subpaths' joins to the camera (and what
//!   the camera sees of the lights straight on).
//! - BDPT: every connection, weighed by multiple importance sampling.
//! - Bidirectional photon mapping: only merges, weighed among themselves.
//! - VCM: both, the merge radius shrinking as pass^−(1−α)/2, so the image
//!   converges where a caustic seen in a mirror leaves BDPT nothing. By
//!   default it merges only where light came through a mirror or glass
//!   (`Strategies::caustic_merges`); merging everywhere is an option.

pub mod camera_paths;
pub mod light_paths;
pub mod merging;
pub mod mis;
pub mod strategies;

use rayon::prelude::*;

use super::photon_map::emit::LightPicker;
use super::{Counters, PassObserver, PassReport, Stage};
use crate::render::film::{Film, TermSums};
use crate::render::settings::{Algorithm, Method, MisHeuristic, RenderSettings};
use crate::render::world::camera::{CameraModel, CameraTile};
use crate::render::world::emission::Bounds;
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::light::LightSource;
use crate::render::world::World;
use crate::scene::Rgb;
use camera_paths::LightSide;
use merging::{MergeBuffers, MergeGrid};
use mis::Strategies;
use strategies::{Contribution, StrategyFilm};

/// Bidirectional work of one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathPassStats {
    pub light_paths: u64,
    pub light_vertices: u64,
    /// Connections traced (to the camera, to lights, between vertices).
    pub connections: u64,
    /// Light vertices merged into camera vertices.
    pub merges: u64,
    /// The merge radius of the pass (0 without merging).
    pub merge_radius: f32,
}

/// Which strategies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    LightTracing,
    Connect,
    Merge,
    ConnectAndMerge,
}

/// One bidirectional method over a film.
pub struct Bidir {
    mode: Mode,
    heuristic: MisHeuristic,
    /// The merge radius of the first pass, and its reduction α.
    radius: f32,
    alpha: f32,
    /// VCM merging only on caustic paths (`Strategies::caustic_merges`).
    caustic_merges: bool,
    max_length: u32,
    seed: u64,
    picker: LightPicker,
    /// What each strategy brought so far, while the view asks for it.
    strategy_film: Option<StrategyFilm>,
    /// The merge grid's records, from pass to pass.
    merge_buffers: MergeBuffers,
}

/// What the subpaths of a pass share.
pub struct Context<'a> {
    pub world: &'a World,
    /// The world for eight rays at a time, where it can be compiled.
    pub lane_world: Option<&'a LaneWorld>,
    pub camera: &'a CameraModel,
    pub strategies: Strategies,
    pub picker: &'a LightPicker,
    /// Where light from the directional lights starts (`Bidir::light_region`).
    pub bounds: Bounds,
    /// Where the background's starts: the photons' region.
    pub sky_bounds: Bounds,
    /// The background light, if the scene has one.
    pub background: Option<usize>,
    /// Longest path, in segments.
    pub max_length: u32,
    /// Plain light tracing: joins to the camera weigh 1, camera paths only
    /// see lights straight on.
    pub light_tracing: bool,
    /// Where the strategy view's contributions go, if it is open.
    pub strategy_film: Option<&'a StrategyFilm>,
}

impl Context<'_> {
    /// Whether light vertices are kept (to connect or merge).
    pub fn keeps_vertices(&self) -> bool {
        self.strategies.connect || self.strategies.merge
    }

    /// Where light from `light` starts, if it is infinite.
    #[inline]
    pub fn bounds_of(&self, light: &LightSource) -> Bounds {
        match light {
            LightSource::Background { .. } => self.sky_bounds,
            _ => self.bounds,
        }
    }
}

impl Bidir {
    /// For `settings`' method (one of the four) on `world`. The merge
    /// radius, when the settings leave it, is a share of what the camera
    /// sees: 2% for BPM (as SPPM starts), whose merges carry every path;
    /// 0.5% for VCM merging everywhere, whose connections carry most paths,
    /// so a wide radius buys little noise and costs bias: light leaking
    /// through a thin wall where a plane runs on past it (gap-room's
    /// partition); 1% for VCM merging on caustic paths, whose merges alone
    /// carry the paths they make, where a wider radius blurs the caustic
    /// (the measurements behind each are in docs/performance.md).
    pub fn new(world: &World, settings: &RenderSettings, visible_radius: f32) -> Self {
        let (mode, heuristic, radius, alpha, caustic_merges) = match &settings.method {
            Method::Bdpt(b) => (Mode::Connect, b.mis, 0.0, 1.0, false),
            // Merges are its only strategy: each path needs them
            Method::Bpm(m) => (Mode::Merge, m.mis, m.radius, m.alpha, false),
            Method::Vcm(m) => (Mode::ConnectAndMerge, m.mis, m.radius, m.alpha, m.caustic_merges),
            _ => (Mode::LightTracing, MisHeuristic::Power, 0.0, 1.0, false),
        };
        let share = match mode {
            Mode::ConnectAndMerge if caustic_merges => 0.01,
            Mode::ConnectAndMerge => 0.005,
            _ => 0.02,
        };
        let radius = if radius > 0.0 { radius } else { (visible_radius * share).max(1e-6) };
        Self {
            mode,
            heuristic,
            radius,
            alpha,
            caustic_merges,
            max_length: settings.max_depth.max(1),
            seed: settings.seed,
            picker: LightPicker::new(world),
            strategy_film: None,
            merge_buffers: MergeBuffers::default(),
        }
    }

    /// The algorithm it is.
    pub fn algorithm(&self) -> Algorithm {
        match self.mode {
            Mode::LightTracing => Algorithm::LightTracing,
            Mode::Connect => Algorithm::Bdpt,
            Mode::Merge => Algorithm::Bpm,
            Mode::ConnectAndMerge => Algorithm::Vcm,
        }
    }

    /// The merge radius of pass `pass` (from 0): r₀ / (pass + 1)^((1−α)/2).
    pub fn merge_radius(&self, pass: u32) -> f32 {
        (self.radius / ((pass + 1) as f32).powf(0.5 * (1.0 - self.alpha))).max(1e-7)
    }

    /// Where light subpaths from directional lights start: what the camera
    /// sees where connections can carry the light that comes from outside
    /// it (BDPT, VCM); with the photons' margin where nothing else would
    /// (light tracing, bidirectional photon mapping). The background's
    /// always start with the margin: camera subpaths find the sky well by
    /// themselves, and more light subpaths in the region seen cost more
    /// time than they save there.
    fn light_region(&self, world: &World) -> Bounds {
        match self.mode {
            Mode::Connect | Mode::ConnectAndMerge => world.seen_bounds(),
            Mode::LightTracing | Mode::Merge => world.bounds(),
        }
    }

    /// The strategies of pass `pass` over `pixels` pixels, and how they weigh.
    fn weighing(&self, pass: u32, pixels: f32) -> Strategies {
        let connect = matches!(self.mode, Mode::Connect | Mode::ConnectAndMerge);
        let merge = matches!(self.mode, Mode::Merge | Mode::ConnectAndMerge);
        Strategies::with_merges(self.heuristic, connect, merge, self.caustic_merges, pixels, self.merge_radius(pass))
    }

    /// One pass: the light subpaths, then the camera subpaths tile by tile,
    /// then the light subpaths' joins to the camera. None if abandoned.
    pub fn pass(
        &mut self,
        stage: &Stage,
        film: &mut Film,
        pass: u32,
        observer: &dyn PassObserver,
    ) -> Option<PassReport> {
        let world = stage.world;
        let pixels = film.width as u64 * film.height as u64;
        // The view opens and closes while the job goes on: counted from the
        // pass it opened at, forgotten when it closes
        if !observer.wants_strategies() {
            self.strategy_film = None;
        } else if self.strategy_film.is_none() {
            self.strategy_film = Some(StrategyFilm::new(film.width, film.height));
        }
        let mut strategy_film = self.strategy_film.take();
        let weighing = self.weighing(pass, pixels as f32);
        let background = world.lights.iter().position(|l| matches!(l, LightSource::Background { .. }));
        let ctx = Context {
            world,
            lane_world: stage.lanes,
            camera: stage.camera,
            strategies: weighing,
            picker: &self.picker,
            bounds: self.light_region(world),
            sky_bounds: world.bounds(),
            background,
            max_length: self.max_length,
            light_tracing: self.mode == Mode::LightTracing,
            strategy_film: strategy_film.as_ref(),
        };
        let keep_going = || observer.is_current();
        let paths = light_paths::trace(&ctx, pixels, pass as u64, self.seed, &keep_going)?;
        let radius = self.merge_radius(pass);
        let grid = weighing
            .merge
            .then(|| MergeGrid::build(&paths, radius, &weighing, std::mem::take(&mut self.merge_buffers)));
        if !observer.is_current() {
            return None;
        }
        let light = LightSide { paths: &paths, grid: grid.as_ref(), radius };
        let streams = stage.streams(pass as u64);
        let width = film.width;
        let per_tile: Vec<(Counters, Vec<Contribution>)> = film
            .tiles
            .par_iter_mut()
            .with_max_len(1)
            .map(|tile| {
                let (mut counters, mut contributions) = (Counters::default(), Vec::new());
                if !observer.is_current() {
                    return (counters, contributions);
                }
                let camera_tile = CameraTile { camera: stage.camera, rect: tile.rect, streams };
                let mut values = vec![Rgb::ZERO; tile.rect.pixels()];
                camera_paths::trace(&ctx, &light, &camera_tile, width, &mut counters, &mut values, &mut contributions);
                for (i, value) in values.into_iter().enumerate() {
                    tile.add(i, stage.accept(value, &mut counters).unwrap_or_default());
                }
                (counters, contributions)
            })
            .collect();
        if !observer.is_current() {
            return None;
        }
        let mut report = PassReport::default();
        report.counters.add(&paths.counters);
        for (counters, _) in &per_tile {
            report.counters.add(counters);
        }
        if let Some(small) = &mut strategy_film {
            // In the order of the work: tiles, then the light paths' chunks
            per_tile.iter().for_each(|(_, contributions)| small.add(contributions));
            paths.contributions.iter().for_each(|contributions| small.add(contributions));
            small.passes += 1;
            if strategies::due(pass) {
                observer.strategies(small.images());
            }
        }
        self.strategy_film = strategy_film;
        if let Some(grid) = grid {
            self.merge_buffers = grid.into_buffers();
        }
        // The joins to the camera, each accepted as a sample is
        let mut rejected = Counters::default();
        let splats: Vec<Vec<_>> = (paths.splats.iter())
            .map(|chunk| {
                (chunk.iter())
                    .filter_map(|splat| {
                        let value = stage.accept(splat.value, &mut rejected)?;
                        Some(crate::render::film::Splat { value, ..*splat })
                    })
                    .collect()
            })
            .collect();
        report.counters.non_finite += rejected.non_finite;
        film.add_splats(splats);
        let noise: Vec<TermSums> = (film.tiles.par_iter_mut())
            .with_max_len(1)
            .map(|tile| {
                tile.samples += 1;
                if observer.wants_tiles() {
                    let variance = if observer.wants_variance() { tile.variance() } else { None };
                    observer.tile(tile.rect, tile.mean(), variance);
                }
                if observer.wants_noise(pass) {
                    tile.noise_terms()
                } else {
                    TermSums::default()
                }
            })
            .collect();
        noise.iter().for_each(|terms| report.noise.add(terms));
        report.paths = PathPassStats {
            light_paths: pixels,
            light_vertices: report.counters.light_vertices,
            connections: report.counters.connections,
            merges: report.counters.merges,
            merge_radius: if weighing.merge { self.merge_radius(pass) } else { 0.0 },
        };
        Some(report)
    }
}
