//! What every algorithm's pass shares: the stage it reads (world, camera,
//! settings, lanes), what it counts and reports, and what it tells its
//! driver.

use std::time::Duration;

use super::bidir;
use super::photon_map::QueryStats;
use crate::render::film::TermSums;
use crate::render::settings::RenderSettings;
use crate::render::world::camera::{CameraModel, TileRect};
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::rng::PassStreams;
use crate::render::world::World;
use crate::scene::Rgb;

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
    pub lanes: Option<&'a LaneWorld>,
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
