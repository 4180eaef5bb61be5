//! Jensen's two photon maps, their statistics, and the radiance estimate.

use std::f32::consts::PI;
use std::time::{Duration, Instant};

use glam::Vec3;

use crate::render::integrators::photon_map::kdtree::{Neighbours, PhotonKdTree};
use crate::render::integrators::photon_map::trace::{trace_photons_until, MapKind, PhotonBatch};
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::materials::Bsdf;
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
    /// Trace both maps, with `seed` and paths of at most `max_depth`.
    pub fn build(world: &World, settings: &PhotonSettings, seed: u64, max_depth: u32) -> Self {
        let lanes = LaneWorld::new(world);
        let built = Self::build_until(world, lanes.as_ref(), settings, seed, max_depth, &|| true);
        built.expect("a build that is never abandoned")
    }

    /// `build` through `lanes` where given, asking `keep_going` before each
    /// chunk of photons (see `trace_photons_until`) and before each tree:
    /// None once it says no.
    pub fn build_until(
        world: &World,
        lanes: Option<&LaneWorld>,
        settings: &PhotonSettings,
        seed: u64,
        max_depth: u32,
        keep_going: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        let build = |kind: MapKind, count: u32| -> Option<(PhotonKdTree, MapStats)> {
            let start = Instant::now();
            let mut photons = Vec::new();
            let batch = PhotonBatch { kind, count: count as u64, pass: 0, seed, max_depth };
            trace_photons_until(world, lanes, batch, keep_going, &mut photons)?;
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
        Some(Self { global, caustic, stats: PhotonMapStats { global: global_stats, caustic: caustic_stats } })
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
    // With nothing found the sum is 0; a radius of 0 (k photons on the
    // point itself) has no density to give
    if radius2 > 0.0 {
        let photons = tree.photons();
        // `k_nearest` kept only photons arriving at the front (wi·n > 0),
        // where a constant BSDF is its constant
        let constant = bsdf.front_constant(wo, normal);
        for &(_, index) in neighbours.as_slice() {
            let photon = &photons[index as usize];
            let f = constant.unwrap_or_else(|| bsdf.eval(wo, -photon.incoming_direction(), normal));
            sum += f * Vec3::from_array(photon.power);
        }
        sum /= PI * radius2;
    }
    stats.time += start.elapsed();
    sum
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI as PI64;

    use super::*;
    use crate::render::integrators::photon_map::record::Photon;

    #[test]
    fn query_stats_add_every_field_and_average_per_query() {
        let mut histogram = [0; RADIUS_BINS];
        histogram[3] = 2;
        let a =
            QueryStats { queries: 4, nodes_visited: 100, time: Duration::from_micros(40), radius_histogram: histogram };
        let mut sum = QueryStats { queries: 1, nodes_visited: 7, time: Duration::from_micros(2), ..Default::default() };
        sum.radius_histogram[0] = 1;
        sum.add(&a);
        sum.add(&a);
        assert_eq!((sum.queries, sum.nodes_visited, sum.time), (9, 207, Duration::from_micros(82)));
        assert_eq!((sum.radius_histogram[0], sum.radius_histogram[3]), (1, 4));
        assert_eq!(sum.mean_nodes_visited(), 23.0);
        assert_eq!(sum.mean_query_time(), Duration::from_nanos(82_000 / 9));
        // No query yet: nothing to divide
        assert_eq!(
            (QueryStats::default().mean_nodes_visited(), QueryStats::default().mean_query_time()),
            (0.0, Duration::ZERO)
        );
    }

    #[test]
    fn a_radius_in_the_settings_is_taken_and_none_is_a_twentieth_of_the_view() {
        let settings = |max_radius| PhotonSettings { max_radius, ..PhotonSettings::default() };
        assert_eq!(resolve_max_radius(10.0, &settings(0.3)), 0.3);
        assert_eq!(resolve_max_radius(10.0, &settings(0.0)), 0.5);
    }

    /// Photons from straight above at 1, 2, …, 20 along x, of power 2 each,
    /// gathered at the origin of a Lambert floor: Σ f Φ / (π r²) over the
    /// k nearest, r the k-th's distance, or the largest radius when fewer
    /// lie within it; each query counted, with its nodes and its radius's bin.
    #[test]
    fn the_estimate_is_the_density_of_the_nearest_photons_and_is_counted() {
        let photons = (1..=20).map(|d| Photon::new(Vec3::new(d as f32, 0.0, 0.0), -Vec3::Y, [2.0; 3])).collect();
        let tree = PhotonKdTree::build(photons);
        let albedo = 0.6;
        let bsdf = Bsdf::lambert(Rgb::splat(albedo));
        let (mut neighbours, mut stats) = (Neighbours::new(8), QueryStats::default());
        let mut gather = |k, max_radius, stats: &mut QueryStats| {
            let value = estimate(&tree, Vec3::ZERO, Vec3::Y, Vec3::Y, &bsdf, k, max_radius, &mut neighbours, stats);
            (value, neighbours.len())
        };
        let expected = |found: f64, radius: f64| (albedo as f64 / PI64) * found * 2.0 / (PI64 * radius * radius);
        // k = 8 within 20: the 8th photon is at 8, in bin ⌊8/20·16⌋ = 6
        let (value, found) = gather(8, 20.0, &mut stats);
        assert_eq!(found, 8);
        assert!((value.x as f64 / expected(8.0, 8.0) - 1.0).abs() < 1e-5, "{value}");
        assert_eq!(value.x, value.z);
        // Only 5 within 5.5: all of them over the whole disc, in the last bin
        let (value, found) = gather(8, 5.5, &mut stats);
        assert_eq!(found, 5);
        assert!((value.x as f64 / expected(5.0, 5.5) - 1.0).abs() < 1e-5, "{value}");
        let mut bins = [0; RADIUS_BINS];
        bins[6] = 1;
        bins[RADIUS_BINS - 1] = 1;
        assert_eq!((stats.queries, stats.radius_histogram), (2, bins));
        let mut out = Neighbours::new(8);
        let visited = tree.k_nearest(Vec3::ZERO, Some(Vec3::Y), 8, 20.0, &mut out)
            + tree.k_nearest(Vec3::ZERO, Some(Vec3::Y), 8, 5.5, &mut out);
        assert_eq!(stats.nodes_visited, visited as u64);
    }
}
