//! Jensen's two photon maps, their statistics, and the radiance estimate.

use std::f32::consts::PI;
use std::time::{Duration, Instant};

use glam::Vec3;

use crate::render::integrators::photon_map::kdtree::{Neighbours, PhotonKdTree};
use crate::render::integrators::photon_map::trace::{trace_photons_until, MapKind};
use crate::render::world::bsdf::Bsdf;
use crate::render::world::World;
use crate::render::PhotonSettings;
use crate::scene::Rgb;

/// Jensen: a k below this makes the estimate noise, not density.
pub const MIN_PHOTONS: usize = 8;
pub const RADIUS_BINS: usize = 16;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapStats {
    pub emitted: u64,
    pub stored: u64,
    pub bytes: u64,
    pub trace_time: Duration,
    pub build_time: Duration,
    pub depth: u32,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonMapStats {
    pub global: MapStats,
    pub caustic: MapStats,
}

/// k-NN work done while rendering, summed per pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QueryStats {
    pub queries: u64,
    pub nodes_visited: u64,
    pub time: Duration,
    /// Gather radii as fractions of the maximum radius, in equal bins.
    pub radius_histogram: [u64; RADIUS_BINS],
}

impl QueryStats {
    pub fn add(&mut self, other: &QueryStats) {
        self.queries += other.queries;
        self.nodes_visited += other.nodes_visited;
        self.time += other.time;
        for (a, b) in self.radius_histogram.iter_mut().zip(other.radius_histogram) {
            *a += b;
        }
    }

    pub fn mean_nodes_visited(&self) -> f64 {
        self.nodes_visited as f64 / self.queries.max(1) as f64
    }

    pub fn mean_query_time(&self) -> Duration {
        self.time / self.queries.max(1) as u32
    }
}

/// The global and caustic maps of one scene and photon settings.
#[derive(Debug)]
pub struct PhotonMaps {
    pub global: PhotonKdTree,
    pub caustic: PhotonKdTree,
    pub stats: PhotonMapStats,
    /// Largest gather radius (resolved from the settings and the scene).
    pub max_radius: f32,
}

/// The gather radius when the settings leave it to the scene: a few percent
/// of the size of what the camera sees (`World::visible_radius`).
pub fn resolve_max_radius(visible_radius: f32, settings: &PhotonSettings) -> f32 {
    if settings.max_radius > 0.0 {
        settings.max_radius
    } else {
        (visible_radius * 0.05).max(1e-6)
    }
}

impl PhotonMaps {
    /// Trace both maps; `visible_radius` sets the default gather radius.
    pub fn build(world: &World, settings: &PhotonSettings, seed: u64, max_depth: u32, visible_radius: f32) -> Self {
        let built = Self::build_until(world, settings, seed, max_depth, visible_radius, &|| true);
        built.expect("a build that is never abandoned")
    }

    /// `build`, asking `keep_going` before each chunk of photons (see
    /// `trace_photons_until`) and before each tree: None once it says no.
    pub fn build_until(
        world: &World,
        settings: &PhotonSettings,
        seed: u64,
        max_depth: u32,
        visible_radius: f32,
        keep_going: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        let build = |kind: MapKind, count: u32| -> Option<(PhotonKdTree, MapStats)> {
            let start = Instant::now();
            let photons = trace_photons_until(world, kind, count as u64, 0, seed, max_depth, keep_going)?;
            let trace_time = start.elapsed();
            if !keep_going() {
                return None;
            }
            let start = Instant::now();
            let tree = PhotonKdTree::build(photons);
            let stats = MapStats {
                emitted: count as u64,
                stored: tree.len() as u64,
                bytes: tree.bytes() as u64,
                trace_time,
                build_time: start.elapsed(),
                depth: tree.depth() as u32,
            };
            Some((tree, stats))
        };
        let (global, global_stats) = build(MapKind::Global, settings.global_photons)?;
        let (caustic, caustic_stats) = build(MapKind::Caustic, settings.caustic_photons)?;
        Some(Self {
            global,
            caustic,
            stats: PhotonMapStats { global: global_stats, caustic: caustic_stats },
            max_radius: resolve_max_radius(visible_radius, settings),
        })
    }
}

/// Reflected radiance from a photon map at a surface point:
/// Σ f·Φ / (π r²) over the k ≥ 8 nearest photons, `r` the distance to the
/// k-th, or the maximum radius when fewer lie within it (then every photon in
/// that disc is in the sum, and the disc is the right area).
/// (The thesis divides by 2π r², a factor of two too small: the photons are
/// counted on a disc of area π r², not a hemisphere.)
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    tree: &PhotonKdTree,
    point: Vec3,
    normal: Vec3,
    wo: Vec3,
    bsdf: &Bsdf,
    k: usize,
    max_radius: f32,
    neighbours: &mut Neighbours,
    stats: &mut QueryStats,
) -> Rgb {
    if tree.is_empty() {
        return Rgb::ZERO;
    }
    let start = Instant::now();
    let visited = tree.k_nearest(point, Some(normal), k, max_radius, neighbours);
    stats.queries += 1;
    stats.nodes_visited += visited as u64;
    let found = neighbours.len();
    debug_assert!(k >= MIN_PHOTONS);
    let radius2 = if found >= k { neighbours.max_dist2() } else { max_radius * max_radius };
    let bin = ((radius2.sqrt() / max_radius) * RADIUS_BINS as f32) as usize;
    stats.radius_histogram[bin.min(RADIUS_BINS - 1)] += 1;
    let mut sum = Rgb::ZERO;
    if found > 0 && radius2 > 0.0 {
        let photons = tree.photons();
        let constant = bsdf.front_constant(wo, normal);
        for &(_, index) in neighbours.as_slice() {
            let photon = &photons[index as usize];
            let wi = -photon.incoming_direction();
            let f = match constant {
                Some(f) if wi.dot(normal) > 0.0 => f,
                Some(_) => Rgb::ZERO,
                None => bsdf.eval(wo, wi, normal),
            };
            sum += f * Vec3::from_array(photon.power);
        }
        sum /= PI * radius2;
    }
    stats.time += start.elapsed();
    sum
}
