//! Whitted ray tracing with the thesis' local models: per light a shadow ray
//! and `kd·Ld·(l·n) + ks·Ls·(r·v)^α` (or `(n·h)^α`), plus `ka·La`; mirrors,
//! Phong highlights' reflectivity and glass by recursion up to a depth limit.
//!
//! The thesis' light colour `Ld` is taken as the light's irradiance over π,
//! so a Lambert surface gets exactly the physical direct term ρ/π·E·cos θ and
//! Whitted images sit beside path-traced ones at the same brightness.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::next_event::PathScope;
use super::Stage;
use crate::geometry::{pow, Ray};
use crate::render::integrators::Counters;
use crate::render::world::bsdf::{reflect, refract};
use crate::render::world::camera::CameraTile;
use crate::render::world::light::{LightSample, LightSource};
use crate::render::world::rng::Sampler;
use crate::render::world::{Hit, World};
use crate::scene::{MaterialModel, Rgb};

/// Below this path weight a reflection adds nothing visible.
const MIN_WEIGHT: f32 = 1e-3;

/// Whitted ray tracing, recursing at most `max_depth` times.
pub struct Whitted {
    pub max_depth: u32,
}

impl Whitted {
    #[inline]
    pub fn radiance(&self, world: &World, ray: &Ray, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
        radiance(world, ray, self.max_depth, sampler, counters)
    }

    /// One sample of every pixel of `tile`, into `out`.
    pub fn render_tile(&self, stage: &Stage, tile: &CameraTile, out: &mut [Rgb], counters: &mut Counters) {
        for (i, value) in out.iter_mut().enumerate() {
            let (ray, mut sampler) = tile.sample(i);
            *value = self.radiance(stage.world, &ray, &mut sampler, counters);
        }
    }
}

/// Radiance along a camera ray, recursing at most `max_depth` times.
pub fn radiance(world: &World, ray: &Ray, max_depth: u32, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
    trace(PathScope::new(world, ray.origin), ray, max_depth, 1.0, sampler, counters)
}

/// The recursion, for a path seen as `scope` sees it; `weight` is what its
/// result is multiplied by on the way to the camera.
fn trace(
    scope: PathScope,
    ray: &Ray,
    depth_left: u32,
    weight: f32,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> Rgb {
    let world = scope.world;
    counters.rays += 1;
    let Some(hit) = scope.intersect(ray) else {
        return world.background;
    };
    let wo = -ray.direction;
    let n = hit.surface.normal;
    let facing = if wo.dot(n) < 0.0 { -n } else { n };
    let can_recurse = depth_left > 1;
    match *world.material_of(&hit) {
        MaterialModel::Emissive { .. } => world.emitted(&hit, wo),
        MaterialModel::Lambert { albedo } => {
            albedo * world.ambient + local(scope, &hit, facing, wo, albedo, Rgb::ZERO, 0.0, false, sampler, counters)
        }
        MaterialModel::Phong { ka, kd, ks, shininess } | MaterialModel::BlinnPhong { ka, kd, ks, shininess } => {
            let blinn = matches!(world.material_of(&hit), MaterialModel::BlinnPhong { .. });
            let mut c =
                ka * world.ambient + local(scope, &hit, facing, wo, kd, ks, shininess, blinn, sampler, counters);
            // The thesis' loop: the surface's reflectivity scales a mirror bounce
            let w = weight * ks.max_element();
            if can_recurse && w > MIN_WEIGHT {
                c += ks
                    * trace(scope, &hit.surface.spawn_ray(reflect(wo, facing)), depth_left - 1, w, sampler, counters);
            }
            c
        }
        MaterialModel::Mirror { tint } => {
            let w = weight * tint.max_element();
            if !can_recurse || w <= MIN_WEIGHT {
                return Rgb::ZERO;
            }
            tint * trace(scope, &hit.surface.spawn_ray(reflect(wo, facing)), depth_left - 1, w, sampler, counters)
        }
        MaterialModel::Glass { ior, tint } => {
            if !can_recurse {
                return Rgb::ZERO;
            }
            let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, ior) } else { (ior, 1.0) };
            let (fresnel, refracted, eta) = refract(wo, facing, eta_i, eta_t);
            let mut c = Rgb::ZERO;
            if weight * fresnel > MIN_WEIGHT {
                let reflected = trace(
                    scope,
                    &hit.surface.spawn_ray(reflect(wo, facing)),
                    depth_left - 1,
                    weight * fresnel,
                    sampler,
                    counters,
                );
                c += fresnel * reflected;
            }
            if let Some(wt) = refracted {
                let w = weight * (1.0 - fresnel);
                if w > MIN_WEIGHT {
                    // Radiance is compressed by η² crossing into the denser side
                    let through = trace(scope, &hit.surface.spawn_ray(wt), depth_left - 1, w, sampler, counters);
                    c += (1.0 - fresnel) * eta * eta * through;
                }
            }
            tint * c
        }
    }
}

/// The local model summed over lights that see the point.
#[allow(clippy::too_many_arguments)]
fn local(
    scope: PathScope,
    hit: &Hit,
    n: Vec3,
    wo: Vec3,
    kd: Rgb,
    ks: Rgb,
    exponent: f32,
    blinn: bool,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> Rgb {
    let mut total = Rgb::ZERO;
    // The background is seen by rays that escape, not as a local light
    for light in scope.world.lights.iter().filter(|l| !matches!(l, LightSource::Background { .. })) {
        // Lights behind the surface are skipped (a NaN goes on, to be counted and dropped)
        let facing = |sample: &LightSample| {
            let cos = n.dot(sample.wi);
            (cos > 0.0 || cos.is_nan()).then_some(cos)
        };
        let Some((sample, cos)) = scope.light_sample(light, hit, sampler.next_2d(), counters, facing) else {
            continue;
        };
        let light_colour = sample.value * FRAC_1_PI;
        let mut c = kd * cos;
        if ks != Rgb::ZERO {
            let highlight = if blinn { n.dot((sample.wi + wo).normalize()) } else { reflect(sample.wi, n).dot(wo) };
            c += ks * pow::powf(highlight.max(0.0), exponent);
        }
        total += light_colour * c;
    }
    total
}
