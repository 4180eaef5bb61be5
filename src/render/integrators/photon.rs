//! Rendering with photon maps (Jensen): camera rays follow mirrors and glass;
//! at the first non-specular surface, direct light by shadow rays, caustics
//! from the caustic map, indirect light from the global map — directly or
//! through a final gather of one bounce.

use std::sync::Arc;

use glam::Vec3;

use super::next_event::lit_sum;
use super::next_event::PathScope;
use super::photon_map::kdtree::Neighbours;
use super::photon_map::maps::{estimate, PhotonMaps, QueryStats};
use super::shadow_batch::ShadowBatch;
use super::specular::{follow_specular, follow_specular_tile, Emission, Landing};
use super::{Counters, Stage};
use crate::geometry::Ray;
use crate::render::settings::PhotonSettings;
use crate::render::world::camera::CameraTile;
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

/// A gather ray's segments through mirrors and glass, the one to its surface
/// included, and one more (`follow_specular` keeps a segment for the light
/// gathered there): it finds its surface after at most three bounces.
const GATHER_SPECULAR_DEPTH: u32 = 5;

/// What one tile reuses between camera samples: no allocation per ray.
pub struct PhotonScratch {
    pub neighbours: Neighbours,
    pub queries: QueryStats,
}

impl PhotonScratch {
    pub fn new(k: usize) -> Self {
        Self { neighbours: Neighbours::new(k), queries: QueryStats::default() }
    }
}

/// Photon mapping with the maps of one job.
pub struct PhotonMapping {
    pub maps: Arc<PhotonMaps>,
    /// The largest gather radius (`maps::resolve_max_radius`).
    max_radius: f32,
    settings: PhotonSettings,
    max_depth: u32,
}

impl PhotonMapping {
    pub fn new(maps: Arc<PhotonMaps>, settings: &PhotonSettings, max_depth: u32, max_radius: f32) -> Self {
        Self { maps, max_radius, settings: settings.clone(), max_depth }
    }

    pub fn scratch(&self) -> PhotonScratch {
        PhotonScratch::new((self.settings.k_nearest as usize).max(super::photon_map::maps::MIN_PHOTONS))
    }

    #[inline]
    pub fn radiance(
        &self,
        world: &World,
        ray: &Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
    ) -> Rgb {
        self.renderer(PathScope::new(world, ray.origin)).radiance(ray, sampler, counters, scratch)
    }

    /// One sample of every pixel of `tile`, each handed to `out` with its
    /// index: `radiance` of each, bit for bit, the camera rays eight at a
    /// time and the shadow rays of every landing's direct light traced together.
    pub fn render_tile(
        &self,
        stage: &Stage,
        tile: &CameraTile,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        let (world, lanes) = (stage.world, stage.lanes);
        let mut scratch = self.scratch();
        let (mut shadows, mut terms) = (ShadowBatch::default(), Vec::new());
        // Each sample's light on the way, and at its landing the throughput,
        // the direct light's terms and the estimates added after them
        let mut found = vec![(Rgb::ZERO, None); tile.len()];
        let land = |i: usize, scope: &PathScope, sampler: &mut Sampler, radiance, landing, counters: &mut Counters| {
            let Some(Landing { hit, wo, bsdf, throughput }) = landing else {
                found[i] = (radiance, None);
                return;
            };
            let renderer = self.renderer(*scope);
            let first = terms.len();
            let (caustic, second) =
                renderer.shade_later(&hit, wo, &bsdf, sampler, counters, &mut scratch, (&mut shadows, &mut terms));
            found[i] = (radiance, Some((throughput, first..terms.len(), caustic, second)));
        };
        follow_specular_tile(world, lanes, tile, self.max_depth, counters, land);
        shadows.trace(lanes, world);
        for (i, (radiance, landed)) in found.into_iter().enumerate() {
            let value = match landed {
                Some((throughput, lit, caustic, second)) => {
                    let mut shade = lit_sum(&terms[lit], &shadows) + caustic;
                    shade += second;
                    radiance + throughput * shade
                }
                None => radiance,
            };
            out(i, value);
        }
        counters.queries.add(&scratch.queries);
    }

    fn renderer<'a>(&'a self, scope: PathScope<'a>) -> PhotonRenderer<'a> {
        let (maps, max_radius) = (&*self.maps, self.max_radius);
        PhotonRenderer { scope, maps, max_radius, settings: &self.settings, max_depth: self.max_depth }
    }
}

struct PhotonRenderer<'a> {
    /// The world as the path being traced sees it.
    scope: PathScope<'a>,
    maps: &'a PhotonMaps,
    max_radius: f32,
    settings: &'a PhotonSettings,
    max_depth: u32,
}

impl PhotonRenderer<'_> {
    fn k(&self) -> usize {
        (self.settings.k_nearest as usize).max(crate::render::integrators::photon_map::maps::MIN_PHOTONS)
    }

    pub fn radiance(
        &self,
        ray: &Ray,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
    ) -> Rgb {
        let (radiance, landing) = follow_specular(&self.scope, ray, self.max_depth, Emission::Count, sampler, counters);
        let Some(Landing { hit, wo, bsdf, throughput }) = landing else { return radiance };
        radiance + throughput * self.shade(&hit, wo, &bsdf, self.settings.final_gather, sampler, counters, scratch)
    }

    /// `shade` of a camera path's landing with its direct light's shadow
    /// rays asked of `later` (its terms pushed there): the caustic
    /// estimate, then what `shade` adds to it, the global map's estimate or
    /// the final gather's.
    #[allow(clippy::too_many_arguments)]
    fn shade_later(
        &self,
        hit: &Hit,
        wo: Vec3,
        bsdf: &Bsdf,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
        (shadows, terms): (&mut ShadowBatch, &mut Vec<(Rgb, u32)>),
    ) -> (Rgb, Rgb) {
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        self.scope.every_light_later(hit, wo, facing, bsdf, sampler, counters, shadows, terms);
        let caustic = self.caustic(hit, wo, facing, bsdf, scratch);
        let second = match self.settings.final_gather {
            false => self.global(hit, wo, facing, bsdf, scratch),
            true => self.final_gather(hit, wo, bsdf, sampler, counters, scratch),
        };
        (caustic, second)
    }

    /// Outgoing radiance at a non-specular hit, emission excluded.
    #[allow(clippy::too_many_arguments)]
    fn shade(
        &self,
        hit: &Hit,
        wo: Vec3,
        bsdf: &Bsdf,
        gather: bool,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
    ) -> Rgb {
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let mut radiance = self.radiance_from_maps(hit, wo, facing, bsdf, !gather, sampler, counters, scratch);
        if gather {
            radiance += self.final_gather(hit, wo, bsdf, sampler, counters, scratch);
        }
        radiance
    }

    /// Indirect light at a non-specular hit by a final gather: the maps'
    /// estimates where its rays land, averaged.
    fn final_gather(
        &self,
        hit: &Hit,
        wo: Vec3,
        bsdf: &Bsdf,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
    ) -> Rgb {
        let rays = self.settings.final_gather_rays.max(1);
        let mut sum = Rgb::ZERO;
        for _ in 0..rays {
            let Some(s) = bsdf.sample(wo, hit.surface.normal, sampler, Transport::Radiance) else {
                continue;
            };
            sum += s.weight * self.gathered(hit.surface.spawn_ray(s.wi), sampler, counters, scratch);
        }
        sum / rays as f32
    }

    /// Radiance arriving along a final-gather ray: the maps' full estimate at
    /// the next non-specular surface. Emitters seen directly (or through
    /// mirrors) are skipped: direct light and caustics already count them.
    fn gathered(&self, ray: Ray, sampler: &mut Sampler, counters: &mut Counters, scratch: &mut PhotonScratch) -> Rgb {
        let emission = Emission::Skip;
        let (radiance, landing) =
            follow_specular(&self.scope, &ray, GATHER_SPECULAR_DEPTH, emission, sampler, counters);
        let Some(Landing { hit, wo, bsdf, throughput }) = landing else { return radiance };
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        throughput * self.radiance_from_maps(&hit, wo, facing, &bsdf, true, sampler, counters, scratch)
    }
}

impl PhotonRenderer<'_> {
    /// Direct light by shadow rays, caustics from the caustic map and, if
    /// asked, indirect light from the global map.
    #[allow(clippy::too_many_arguments)]
    fn radiance_from_maps(
        &self,
        hit: &Hit,
        wo: Vec3,
        facing: Vec3,
        bsdf: &Bsdf,
        global: bool,
        sampler: &mut Sampler,
        counters: &mut Counters,
        scratch: &mut PhotonScratch,
    ) -> Rgb {
        let mut radiance = self.scope.every_light(hit, wo, facing, bsdf, sampler, counters);
        radiance += self.caustic(hit, wo, facing, bsdf, scratch);
        if global {
            radiance += self.global(hit, wo, facing, bsdf, scratch);
        }
        radiance
    }

    /// The caustic map's estimate at `hit`.
    fn caustic(&self, hit: &Hit, wo: Vec3, facing: Vec3, bsdf: &Bsdf, scratch: &mut PhotonScratch) -> Rgb {
        let (point, k, r) = (hit.surface.point, self.k(), self.max_radius);
        let PhotonScratch { neighbours, queries } = scratch;
        estimate(&self.maps.caustic, point, facing, wo, bsdf, k, r, neighbours, queries)
    }

    /// The global map's estimate at `hit`.
    fn global(&self, hit: &Hit, wo: Vec3, facing: Vec3, bsdf: &Bsdf, scratch: &mut PhotonScratch) -> Rgb {
        let (point, k, r) = (hit.surface.point, self.k(), self.max_radius);
        let PhotonScratch { neighbours, queries } = scratch;
        estimate(&self.maps.global, point, facing, wo, bsdf, k, r, neighbours, queries)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::photon_map::maps::resolve_max_radius;
    use crate::render::settings::RenderSettings;
    use crate::render::world::camera::{CameraModel, TileRect};
    use crate::render::world::lane_world::LaneWorld;
    use crate::render::world::rng::PassStreams;
    use crate::scene::presets;

    /// Every preset, reading the global map directly and through a final
    /// gather: a tile rendered with its camera rays eight at a time (or one)
    /// and its landings' shadow rays traced together is `radiance` sample by
    /// sample — the same light, rays and queries, bit for bit.
    #[test]
    fn a_tile_is_radiance_sample_by_sample() {
        for name in presets::names() {
            let scene = presets::preset(name).and_then(Result::ok).expect("preset");
            let (width, height) = (32, 24);
            let camera = CameraModel::new(&scene.camera, width, height);
            let (world, visible_radius) = World::for_view(&scene, &camera, width, height);
            for final_gather in [false, true] {
                let settings = PhotonSettings {
                    global_photons: 4000,
                    caustic_photons: 4000,
                    k_nearest: 20,
                    final_gather,
                    final_gather_rays: 3,
                    ..PhotonSettings::default()
                };
                let compiled = LaneWorld::new(&world);
                let maps = PhotonMaps::build_until(&world, compiled.as_ref(), &settings, 3, 8, &|| true).expect("maps");
                let max_radius = resolve_max_radius(visible_radius, &settings);
                let photon = PhotonMapping::new(Arc::new(maps), &settings, 8, max_radius);
                let rect = TileRect { x: 3, y: 2, width: 21, height: 9 };
                let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(2, 9) };
                let (mut expected_counters, mut scratch) = (Counters::default(), photon.scratch());
                let expected: Vec<[u32; 3]> = (0..tile.len())
                    .map(|i| {
                        let (ray, mut sampler) = tile.sample(i);
                        let value = photon.radiance(&world, &ray, &mut sampler, &mut expected_counters, &mut scratch);
                        value.to_array().map(f32::to_bits)
                    })
                    .collect();
                expected_counters.queries.add(&scratch.queries);
                let settings = RenderSettings::default();
                for lanes in [true, false] {
                    let lanes_if = compiled.as_ref().filter(|_| lanes);
                    let stage = Stage { world: &world, camera: &camera, settings: &settings, lanes: lanes_if };
                    let (mut out, mut counters) = (vec![Rgb::splat(-1.0); tile.len()], Counters::default());
                    photon.render_tile(&stage, &tile, &mut |i, v| out[i] = v, &mut counters);
                    let got: Vec<[u32; 3]> = out.iter().map(|v| v.to_array().map(f32::to_bits)).collect();
                    let what = format!("{name}, final gather {final_gather}, lanes {lanes}");
                    assert!(got == expected, "{what}: the light differs");
                    // Everything counted but the queries' time
                    let counted = |c: &Counters| {
                        let q = &c.queries;
                        (c.rays, c.non_finite, q.queries, q.nodes_visited, q.radius_histogram)
                    };
                    assert_eq!(counted(&counters), counted(&expected_counters), "{what}");
                }
                let lit = expected.iter().filter(|v| v.iter().any(|&c| c != 0)).count();
                assert!(lit > tile.len() / 4, "{name}: only {lit} samples lit");
            }
        }
    }
}
