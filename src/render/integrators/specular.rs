//! A camera ray followed through mirrors and glass to the first surface
//! that is not specular, as photon mapping and SPPM both start their
//! estimates: the light met on the way (emission seen through the chain, the
//! background if it escapes) and where it lands.

use glam::Vec3;

use super::next_event::PathScope;
use super::Counters;
use crate::geometry::Ray;
use crate::render::world::bsdf::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::Hit;
use crate::scene::Rgb;

/// The first non-specular surface a camera path reaches.
pub struct Landing {
    pub hit: Hit,
    /// Toward the camera.
    pub wo: Vec3,
    pub bsdf: Bsdf,
    /// The path's throughput up to the surface.
    pub throughput: Rgb,
}

/// Whether emitters met on the way count.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Emission {
    /// A camera path's: found only through specular bounces, never
    /// light-sampled, so it counts whole (the background's too).
    Count,
    /// A final-gather ray's: direct light and caustics already hold it (the
    /// background is a light too).
    Skip,
}

/// Follow `ray` for at most `max_depth` segments: the radiance gathered on
/// the way and the landing, if the path reaches one.
pub fn follow_specular(
    scope: &PathScope,
    ray: &Ray,
    max_depth: u32,
    emission: Emission,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> (Rgb, Option<Landing>) {
    let world = scope.world;
    let mut ray = *ray;
    let mut throughput = Rgb::ONE;
    let mut radiance = Rgb::ZERO;
    for _ in 0..max_depth {
        counters.rays += 1;
        let Some(hit) = scope.intersect(&ray) else {
            let sky = if emission == Emission::Count { throughput * world.background } else { Rgb::ZERO };
            return (radiance + sky, None);
        };
        let wo = -ray.direction;
        if emission == Emission::Count {
            radiance += throughput * world.emitted(&hit, wo);
        }
        let bsdf = Bsdf::new(world.material_of(&hit));
        if !bsdf.is_specular() {
            return (radiance, Some(Landing { hit, wo, bsdf, throughput }));
        }
        let Some(s) = bsdf.sample(wo, hit.surface.normal, sampler, Transport::Radiance) else {
            break;
        };
        throughput *= s.weight;
        ray = hit.surface.spawn_ray(s.wi);
    }
    (radiance, None)
}
