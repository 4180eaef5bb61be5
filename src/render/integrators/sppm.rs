//! Stochastic progressive photon mapping (Hachisuka & Jensen 2009). Each pass
//! finds one visible point per pixel, traces new photons, and shrinks each
//! pixel's gather radius as photons accumulate (N' = N + αM,
//! R' = R·√(N'/(N + M)), τ' = (τ + Φ)·R'²/R²), so the estimate is
//! consistent: its error keeps falling where fixed-k photon mapping
//! plateaus. Direct light is sampled at the visible points; photons carry
//! only light after its first bounce.

use std::f32::consts::PI;
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::next_event::lit_sum;
use super::next_event::PathScope;
use super::photon_map::grid::PhotonGrid;
use super::photon_map::trace::{trace_photons_until, MapKind, PhotonBatch};
use super::photon_map::Photon;
use super::shadow_batch::ShadowBatch;
use super::specular::{follow_specular, follow_specular_tile, Emission, Landing};
use super::{Counters, PassObserver, PassReport, SppmTimes, Stage};
use crate::faults::{self, Fault};
use crate::geometry::Ray;
use crate::render::film::Film;
use crate::render::settings::{RenderSettings, SppmSettings};
use crate::render::world::camera::CameraTile;
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::materials::Bsdf;
use crate::render::world::rng::Sampler;
use crate::render::world::World;
use crate::scene::Rgb;

/// SPPM over a film: every pixel's progressive state, tile by tile as the
/// film's tiles are.
pub struct Sppm {
    pixels: Vec<Vec<SppmPixel>>,
    initial_radius: f32,
    photons_per_pass: u64,
    alpha: f32,
    max_depth: u32,
    seed: u64,
    /// The last pass's photons: each pass traces into their memory.
    photons: Vec<Photon>,
}

impl Sppm {
    /// The starting radius is the settings', or 2% of what the camera sees.
    pub fn new(film: &Film, sppm: &SppmSettings, settings: &RenderSettings, visible_radius: f32) -> Self {
        let initial_radius =
            if sppm.initial_radius > 0.0 { sppm.initial_radius } else { (visible_radius * 0.02).max(1e-6) };
        Self {
            pixels: film.tiles.iter().map(|t| vec![SppmPixel::default(); t.sums.len()]).collect(),
            initial_radius,
            photons_per_pass: sppm.photons_per_pass as u64,
            alpha: sppm.alpha,
            max_depth: settings.max_depth,
            seed: settings.seed,
            photons: Vec::new(),
        }
    }

    /// Light found along a camera ray up to its visible point (the preview).
    pub fn direct(&self, world: &World, ray: &Ray, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
        camera_pass(world, ray, self.max_depth, sampler, counters).0
    }

    /// What tile `tile` shows after the passes so far.
    pub fn tile_pixels(&self, film: &Film, tile: usize) -> Vec<[f32; 3]> {
        let passes = film.tiles[tile].samples;
        self.pixels[tile].iter().map(|p| p.value(passes).to_array()).collect()
    }

    /// One pass: visible points for every pixel, this pass's photons, then
    /// each pixel's update. None if the job was abandoned.
    pub fn pass(
        &mut self,
        stage: &Stage,
        film: &mut Film,
        pass: u32,
        observer: &dyn PassObserver,
    ) -> Option<PassReport> {
        let streams = stage.streams(pass as u64);
        let initial_radius = self.initial_radius;
        let (max_depth, lanes) = (self.max_depth, stage.lanes);
        let mut report = PassReport::default();
        let eye_start = Instant::now();
        let per_tile: Vec<Counters> = (film.tiles.par_iter())
            .zip(self.pixels.par_iter_mut())
            .with_max_len(1)
            .map(|(tile, pixels)| {
                let mut counters = Counters::default();
                if !observer.is_current() {
                    return counters;
                }
                let camera_tile = CameraTile { camera: stage.camera, rect: tile.rect, streams };
                for (pixel, direct) in
                    pixels.iter_mut().zip(eye_pass(stage.world, lanes, &camera_tile, max_depth, &mut counters))
                {
                    pixel.direct += stage.accept(direct.0, &mut counters).unwrap_or(Rgb::ZERO);
                    pixel.visible = direct.1;
                    if pixel.radius == 0.0 {
                        pixel.radius = initial_radius;
                    }
                }
                counters
            })
            .collect();
        if !observer.is_current() {
            return None;
        }
        for counters in &per_tile {
            report.counters.add(counters);
        }
        let mut times = SppmTimes { eye: eye_start.elapsed(), ..SppmTimes::default() };
        let trace_start = Instant::now();
        let count = self.photons_per_pass;
        let keep_going = || observer.is_current();
        let batch = PhotonBatch { kind: MapKind::Indirect, count, pass: pass as u64, seed: self.seed, max_depth };
        let photons = &mut self.photons;
        trace_photons_until(stage.world, stage.lanes, batch, &keep_going, photons)?;
        times.trace = trace_start.elapsed();
        report.photon.photons_traced = count;
        report.photon.photons_stored = photons.len() as u64;
        let build_start = Instant::now();
        // Cells as wide as the widest radius: a query touches 3×3×3 of them
        let widest = (self.pixels.iter().flatten())
            .filter(|p| p.visible.is_some())
            .fold(0.0f32, |widest, p| widest.max(p.radius));
        let grid = PhotonGrid::build(photons, widest);
        times.build = build_start.elapsed();
        if !observer.is_current() {
            return None;
        }
        let gather_start = Instant::now();
        let alpha = self.alpha;
        let radii: Vec<(f64, usize)> = (film.tiles.par_iter_mut())
            .zip(self.pixels.par_iter_mut())
            .with_max_len(1)
            .map(|(tile, pixels)| {
                if !observer.is_current() {
                    return (0.0, 0);
                }
                let mut sum = 0.0;
                for pixel in pixels.iter_mut() {
                    pixel.gather(&grid, alpha);
                    sum += pixel.radius as f64;
                }
                tile.samples += 1;
                if observer.wants_tiles() {
                    let pixels = pixels.iter().map(|p| p.value(tile.samples).to_array()).collect();
                    observer.tile(tile.rect, pixels, None);
                }
                (sum, pixels.len())
            })
            .collect();
        // Abandoned while gathering: the film has some tiles of this pass and not others
        if !observer.is_current() {
            return None;
        }
        times.gather = gather_start.elapsed();
        report.photon.times = times;
        let (sum, count) = radii.iter().fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        report.photon.mean_radius = (sum / count.max(1) as f64) as f32;
        Some(report)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub point: Vec3,
    /// Normal on the side the camera path arrived from.
    pub facing: Vec3,
    pub wo: Vec3,
    pub bsdf: Bsdf,
    /// Camera path throughput up to the point.
    pub throughput: Rgb,
}

/// One pixel's progressive state.
#[derive(Clone, Copy, Debug, Default)]
pub struct SppmPixel {
    pub radius: f32,
    /// Accumulated photon count N (fractional by α).
    pub photons: f32,
    /// Accumulated flux τ.
    pub flux: Rgb,
    /// Sum over passes of emitted and direct light along the camera path.
    pub direct: Rgb,
    pub visible: Option<VisiblePoint>,
}

impl SppmPixel {
    /// The pixel's estimate after `passes` passes.
    pub fn value(&self, passes: u32) -> Rgb {
        if passes == 0 {
            return Rgb::ZERO;
        }
        let mut indirect = if self.radius > 0.0 { self.flux / (PI * self.radius * self.radius) } else { Rgb::ZERO };
        if faults::active(Fault::SppmDensityHigh) {
            indirect *= 1.02;
        }
        (self.direct + indirect) / passes as f32
    }

    /// Gather this pass's photons at the visible point and update the
    /// radius, count and flux.
    pub fn gather(&mut self, grid: &PhotonGrid, alpha: f32) {
        let Some(vp) = self.visible.take() else {
            return;
        };
        // A constant BSDF multiplies the photons' summed power; any other is
        // evaluated photon by photon
        let (flux, found) = match vp.bsdf.front_constant(vp.wo, vp.facing) {
            Some(f) => {
                let found = grid.gather_front(vp.point, self.radius, vp.facing, |_| {});
                (f * found.power, found.count)
            }
            None => {
                let mut flux = Rgb::ZERO;
                let found = grid.gather_front(vp.point, self.radius, vp.facing, |i| {
                    flux += vp.bsdf.eval(vp.wo, -grid.incoming(i), vp.facing) * grid.power(i);
                });
                (flux, found.count)
            }
        };
        if found == 0 {
            return;
        }
        let m = found as f32;
        let alpha = if faults::active(Fault::SppmRadiusFixed) { 1.0 } else { alpha };
        let photons = self.photons + alpha * m;
        let radius = self.radius * (photons / (self.photons + m)).sqrt();
        let shrink = (radius / self.radius).powi(2);
        self.flux = (self.flux + vp.throughput * flux) * shrink;
        self.photons = photons;
        self.radius = radius;
    }
}

/// Trace a camera ray through specular bounces to its visible point,
/// returning the light found on the way (emission and the background seen
/// through specular chains, direct light at the point, the background's
/// among it) and the point.
pub fn camera_pass(
    world: &World,
    ray: &Ray,
    max_depth: u32,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> (Rgb, Option<VisiblePoint>) {
    let scope = PathScope::new(world, ray.origin);
    let (mut radiance, landing) = follow_specular(&scope, ray, max_depth, Emission::Count, sampler, counters);
    let Some(Landing { hit, wo, bsdf, throughput }) = landing else { return (radiance, None) };
    let n = hit.surface.normal;
    let facing = if wo.dot(n) < 0.0 { -n } else { n };
    radiance += throughput * scope.every_light(&hit, wo, facing, &bsdf, sampler, counters);
    let visible = VisiblePoint { point: hit.surface.point, facing, wo, bsdf, throughput };
    (radiance, Some(visible))
}

/// `camera_pass` of every camera sample of `tile`: the rays eight at a
/// time through `lanes` where given, the shadow rays of every visible
/// point's direct light traced together; the same light bit for bit.
pub fn eye_pass(
    world: &World,
    lanes: Option<&LaneWorld>,
    tile: &CameraTile,
    max_depth: u32,
    counters: &mut Counters,
) -> Vec<(Rgb, Option<VisiblePoint>)> {
    let (mut shadows, mut terms) = (ShadowBatch::default(), Vec::new());
    // Each sample's light on the way, its visible point and its direct light's terms
    let mut found = vec![(Rgb::ZERO, None, 0..0); tile.len()];
    follow_specular_tile(world, lanes, tile, max_depth, counters, |i, scope, sampler, radiance, landing, counters| {
        let Some(Landing { hit, wo, bsdf, throughput }) = landing else {
            found[i] = (radiance, None, 0..0);
            return;
        };
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let first = terms.len();
        scope.every_light_later(&hit, wo, facing, &bsdf, sampler, counters, &mut shadows, &mut terms);
        let visible = VisiblePoint { point: hit.surface.point, facing, wo, bsdf, throughput };
        found[i] = (radiance, Some(visible), first..terms.len());
    });
    shadows.trace(lanes, world);
    (found.into_iter())
        .map(|(radiance, visible, lit)| match visible {
            Some(v) => (radiance + v.throughput * lit_sum(&terms[lit], &shadows), Some(v)),
            None => (radiance, None),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::photon_map::Photon;
    use crate::render::world::camera::{CameraModel, TileRect};
    use crate::render::world::rng::PassStreams;
    use crate::scene::presets;

    /// Every preset, at depth caps of one, two and eight: a tile's eye
    /// pass, its rays eight at a time or one, finds what `camera_pass`
    /// finds sample by sample — the same light, visible points and rays
    /// counted, bit for bit.
    #[test]
    fn a_tiles_eye_pass_is_camera_pass_sample_by_sample() {
        for name in presets::names() {
            let scene = presets::preset(name).and_then(Result::ok).expect("preset");
            let (width, height) = (40, 30);
            let camera = CameraModel::new(&scene.camera, width, height);
            let (world, _) = World::for_view(&scene, &camera, width, height);
            let lanes = LaneWorld::new(&world);
            let rect = TileRect { x: 3, y: 2, width: 29, height: 11 };
            let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(1, 4) };
            for max_depth in [1, 2, 8] {
                let mut expected_counters = Counters::default();
                let expected: Vec<String> = (0..tile.len())
                    .map(|i| {
                        let (ray, mut sampler) = tile.sample(i);
                        let found = camera_pass(&world, &ray, max_depth, &mut sampler, &mut expected_counters);
                        format!("{:?} {:?}", found.0.to_array().map(f32::to_bits), found.1)
                    })
                    .collect();
                for lanes in [lanes.as_ref(), None] {
                    let mut counters = Counters::default();
                    let got: Vec<String> = (eye_pass(&world, lanes, &tile, max_depth, &mut counters).iter())
                        .map(|found| format!("{:?} {:?}", found.0.to_array().map(f32::to_bits), found.1))
                        .collect();
                    assert!(
                        got == expected,
                        "{name}, depth {max_depth}, lanes {}: the eye pass differs",
                        lanes.is_some()
                    );
                    assert_eq!(counters.rays, expected_counters.rays, "{name}, depth {max_depth}");
                }
                // At depth 1 no segment is left to gather over
                let visible = expected.iter().filter(|e| e.contains("Some")).count();
                assert!((visible > tile.len() / 5) == (max_depth > 1), "{name}: {visible} visible points");
            }
        }
    }

    #[test]
    fn radius_shrinks_stays_positive_and_finite_over_thousands_of_passes() {
        let photons: Vec<Photon> =
            (0..50).map(|i| Photon::new(Vec3::new(i as f32 * 1e-3, 0.0, 0.0), -Vec3::Y, [1.0; 3])).collect();
        let grid = PhotonGrid::build(&photons, 0.1);
        let mut pixel = SppmPixel { radius: 0.1, ..Default::default() };
        let mut last = pixel.radius;
        for pass in 1..=5000u32 {
            pixel.visible = Some(VisiblePoint {
                point: Vec3::ZERO,
                facing: Vec3::Y,
                wo: Vec3::Y,
                bsdf: Bsdf::lambert(Vec3::splat(0.5)),
                throughput: Rgb::ONE,
            });
            pixel.gather(&grid, 2.0 / 3.0);
            assert!(pixel.radius > 0.0 && pixel.radius.is_finite() && pixel.radius <= last);
            assert!(pixel.value(pass).is_finite());
            last = pixel.radius;
        }
        assert!(pixel.radius < 0.1);
    }
}
