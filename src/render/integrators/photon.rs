//! Rendering with photon maps (Jensen): camera rays follow mirrors and glass;
//! at the first non-specular surface, direct light by shadow rays, caustics
//! from the caustic map, indirect light from the global map — directly or
//! through a final gather of one bounce.

use std::sync::Arc;

use glam::Vec3;

use super::next_event::PathScope;
use super::photon_map::kdtree::Neighbours;
use super::photon_map::maps::{estimate, PhotonMaps, QueryStats};
use super::specular::{follow_specular, Emission, Landing};
use super::{Counters, Stage};
use crate::geometry::Ray;
use crate::render::settings::PhotonSettings;
use crate::render::world::bsdf::{Bsdf, Transport};
use crate::render::world::camera::CameraTile;
use crate::render::world::rng::Sampler;
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

/// Specular bounces a gather ray may follow before it must find a surface.
const GATHER_SPECULAR_DEPTH: u32 = 4;

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
    settings: PhotonSettings,
    max_depth: u32,
}

impl PhotonMapping {
    pub fn new(maps: Arc<PhotonMaps>, settings: &PhotonSettings, max_depth: u32) -> Self {
        Self { maps, settings: settings.clone(), max_depth }
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
        let renderer = PhotonRenderer {
            scope: PathScope::new(world, ray.origin),
            maps: &self.maps,
            settings: &self.settings,
            max_depth: self.max_depth,
        };
        renderer.radiance(ray, sampler, counters, scratch)
    }

    /// One sample of every pixel of `tile`, into `out`.
    pub fn render_tile(&self, stage: &Stage, tile: &CameraTile, out: &mut [Rgb], counters: &mut Counters) {
        let mut scratch = self.scratch();
        for (i, value) in out.iter_mut().enumerate() {
            let (ray, mut sampler) = tile.sample(i);
            *value = self.radiance(stage.world, &ray, &mut sampler, counters, &mut scratch);
        }
        counters.queries.add(&scratch.queries);
    }
}

struct PhotonRenderer<'a> {
    /// The world as the path being traced sees it.
    scope: PathScope<'a>,
    maps: &'a PhotonMaps,
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
            let rays = self.settings.final_gather_rays.max(1);
            let mut sum = Rgb::ZERO;
            for _ in 0..rays {
                let Some(s) = bsdf.sample(wo, n, sampler, Transport::Radiance) else {
                    continue;
                };
                sum += s.weight * self.gathered(hit.surface.spawn_ray(s.wi), sampler, counters, scratch);
            }
            radiance += sum / rays as f32;
        }
        radiance
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
        let (point, k, r) = (hit.surface.point, self.k(), self.maps.max_radius);
        let mut radiance = self.scope.every_light(hit, wo, facing, bsdf, sampler, counters);
        radiance +=
            estimate(&self.maps.caustic, point, facing, wo, bsdf, k, r, &mut scratch.neighbours, &mut scratch.queries);
        if global {
            radiance += estimate(
                &self.maps.global,
                point,
                facing,
                wo,
                bsdf,
                k,
                r,
                &mut scratch.neighbours,
                &mut scratch.queries,
            );
        }
        radiance
    }
}
