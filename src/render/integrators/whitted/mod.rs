//! Whitted ray tracing with the thesis' local models: per light a shadow ray
//! and `kd·Ld·(l·n) + ks·Ls·(r·v)^α` (or `(n·h)^α`), plus `ka·La`; mirrors,
//! Phong highlights' reflectivity and glass by recursion up to a depth limit.
//!
//! The thesis' light colour `Ld` is taken as the light's irradiance over π,
//! so a Lambert surface gets exactly the physical direct term ρ/π·E·cos θ and
//! Whitted images sit beside path-traced ones at the same brightness.
//!
//! A pixel's rays, by recursion here (`radiance`); a tile's, wave by wave
//! with their rays and shadow rays eight at a time (`waves`), the same
//! light bit for bit.

mod shading;
mod waves;

use super::next_event::PathScope;
use super::Stage;
use crate::geometry::Ray;
use crate::render::integrators::Counters;
use crate::render::world::camera::CameraTile;
use crate::render::world::light::LightSource;
use crate::render::world::materials::Bsdf;
use crate::render::world::rng::Sampler;
use crate::render::world::World;
use crate::scene::Rgb;
use shading::{branches, combine, light_term, lit_cosine};

/// Whitted ray tracing: at most `rays` rays in a chain through mirrors and
/// glass, each hit lit by shadow rays.
pub struct Whitted {
    pub rays: u32,
}

impl Whitted {
    /// Paths of at most `max_depth` segments, the shadow ray's included;
    /// what the camera sees is always shaded.
    pub fn new(max_depth: u32) -> Self {
        Self { rays: max_depth.saturating_sub(1).max(1) }
    }

    #[inline]
    pub fn radiance(&self, world: &World, ray: &Ray, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
        radiance(world, ray, self.rays, sampler, counters)
    }

    /// One sample of every pixel of `tile`, each handed to `out` with its
    /// index once the tile is done (its waves add to every pixel).
    pub fn render_tile(
        &self,
        stage: &Stage,
        tile: &CameraTile,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        let mut values = vec![Rgb::ZERO; tile.len()];
        waves::render_tile(stage.world, stage.lanes, tile, self.rays, &mut values, counters);
        values.into_iter().enumerate().for_each(|(i, value)| out(i, value));
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
    // The material once a hit, not once a light
    let bsdf = Bsdf::new(world.material_of(&hit));
    let mut local = Rgb::ZERO;
    if bsdf.thesis_lit() {
        let at = shading::at(ray, &hit);
        let n = at.facing.into();
        // The background is seen by rays that escape, not as a local light
        for light in world.lights.iter().filter(|l| !matches!(l, LightSource::Background { .. })) {
            let lit = |sample: &_| lit_cosine(n, sample);
            if let Some((sample, cos)) = scope.light_sample(light, &hit, sampler.next_2d(), counters, lit) {
                local += light_term(&bsdf, &at, &sample, cos);
            }
        }
    }
    let branches = branches(world, ray, &hit, depth_left, weight);
    let mut follow = |branch: Option<(Ray, f32)>| match branch {
        Some((ray, w)) => trace(scope, &ray, depth_left - 1, w, sampler, counters),
        None => Rgb::ZERO,
    };
    let reflected = follow(branches.reflected);
    let refracted = follow(branches.refracted);
    combine(world, ray, &hit, local, [reflected, refracted], &branches)
}
