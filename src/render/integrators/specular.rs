//! A camera ray followed through mirrors and glass to the first surface
//! that is not specular, as photon mapping and SPPM both start their
//! estimates: the light met on the way (emission seen through the chain, the
//! background if it escapes) and where it lands. One ray at a time
//! (`follow_specular`), or a tile's eight at a time (`follow_specular_tile`),
//! the same steps on the same random streams.

use glam::Vec3;

use super::next_event::PathScope;
use super::{flying, Counters};
use crate::geometry::Ray;
use crate::render::world::camera::CameraTile;
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::{Hit, World};
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

/// A path between its specular bounces.
struct Chain {
    ray: Ray,
    throughput: Rgb,
    radiance: Rgb,
    /// Segments it may still trace, `ray`'s included.
    segments: u32,
}

impl Chain {
    fn new(ray: Ray, max_depth: u32) -> Self {
        Chain { ray, throughput: Rgb::ONE, radiance: Rgb::ZERO, segments: max_depth }
    }

    /// The path at its ray's nearest hit (None: it escaped): where it ends,
    /// with the light found on the way and its landing, if it does.
    fn step(
        &mut self,
        world: &World,
        hit: Option<&Hit>,
        emission: Emission,
        sampler: &mut Sampler,
    ) -> Option<(Rgb, Option<Landing>)> {
        let Some(&hit) = hit else {
            let sky = if emission == Emission::Count { self.throughput * world.background } else { Rgb::ZERO };
            return Some((self.radiance + sky, None));
        };
        let wo = -self.ray.direction;
        if emission == Emission::Count {
            self.radiance += self.throughput * world.emitted(&hit, wo);
        }
        let bsdf = Bsdf::new(world.material_of(&hit));
        // A landing gathers light over one segment more (a shadow ray's, a
        // photon's): at the last segment's end there is none left
        if self.segments == 1 {
            return Some((self.radiance, None));
        }
        if !bsdf.is_specular() {
            return Some((self.radiance, Some(Landing { hit, wo, bsdf, throughput: self.throughput })));
        }
        let Some(s) = bsdf.sample(wo, hit.surface.normal, sampler, Transport::Radiance) else {
            return Some((self.radiance, None));
        };
        self.throughput *= s.weight;
        self.ray = hit.surface.spawn_ray(s.wi);
        self.segments -= 1;
        None
    }
}

/// Follow `ray` for at most `max_depth` segments: the radiance gathered on
/// the way and the landing, if the path reaches one before its last
/// segment's end.
pub fn follow_specular(
    scope: &PathScope,
    ray: &Ray,
    max_depth: u32,
    emission: Emission,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> (Rgb, Option<Landing>) {
    if max_depth == 0 {
        return (Rgb::ZERO, None);
    }
    let mut chain = Chain::new(*ray, max_depth);
    loop {
        counters.rays += 1;
        let hit = scope.intersect(&chain.ray);
        if let Some(end) = chain.step(scope.world, hit.as_ref(), emission, sampler) {
            return end;
        }
    }
}

/// One camera path of a tile in flight.
struct CameraChain<'w> {
    scope: PathScope<'w>,
    sampler: Sampler,
    chain: Chain,
}

/// `follow_specular` of every camera sample of `tile` (emission counted),
/// eight at a time through `lanes` where given: `land` is told each
/// sample's index, the path's scope and random stream (past what the chain
/// drew), the light met on the way and the landing. In no fixed order of
/// the samples.
pub fn follow_specular_tile(
    world: &World,
    lanes: Option<&LaneWorld>,
    tile: &CameraTile,
    max_depth: u32,
    counters: &mut Counters,
    mut land: impl FnMut(usize, &PathScope, &mut Sampler, Rgb, Option<Landing>, &mut Counters),
) {
    let count = tile.len();
    if max_depth == 0 {
        for i in 0..count {
            let (ray, mut sampler) = tile.sample(i);
            land(i, &PathScope::new(world, ray.origin), &mut sampler, Rgb::ZERO, None, counters);
        }
        return;
    }
    let launch = |i: u64| {
        let (ray, sampler) = tile.sample(i as usize);
        Some(CameraChain { scope: PathScope::new(world, ray.origin), sampler, chain: Chain::new(ray, max_depth) })
    };
    let mut rays = 0;
    let ray = |path: &CameraChain| {
        rays += 1;
        (path.chain.ray, path.scope.held)
    };
    let bounce = |place: u32, path: &mut CameraChain, hit: Option<&Hit>| match path.chain.step(
        world,
        hit,
        Emission::Count,
        &mut path.sampler,
    ) {
        Some((radiance, landing)) => {
            land(place as usize, &path.scope, &mut path.sampler, radiance, landing, counters);
            false
        }
        None => true,
    };
    flying::fly(lanes, world, 0..count as u64, launch, ray, bounce);
    counters.rays += rays;
}
