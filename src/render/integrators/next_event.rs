//! Next-event estimation, written once: a light sample toward a shading
//! point, what the integrator makes of it, the shadow ray. Each algorithm
//! chooses its policy on top: path tracing one light with MIS, photon
//! mapping and SPPM every light, Whitted every light through the thesis'
//! local models.

use glam::{Vec2, Vec3};

use super::shadow_batch::ShadowBatch;
use super::Counters;
use crate::geometry::Ray;
use crate::render::world::light::{LightSample, LightSource};
use crate::render::world::materials::Bsdf;
use crate::render::world::occluders::{Occluders, Shadow};
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::power_heuristic;
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

/// The world as one path sees it: its shapes, and, depending on where the
/// path started, whether it is held inside the walls (which it then meets
/// only on their way out) and what can block its shadow rays.
#[derive(Clone, Copy)]
pub struct PathScope<'w> {
    pub world: &'w World,
    pub held: bool,
    pub occluders: Occluders<'w>,
}

impl<'w> PathScope<'w> {
    /// For a path that starts at `origin` (a camera ray's, a light's).
    #[inline]
    pub fn new(world: &'w World, origin: Vec3) -> Self {
        let held = world.holds(origin);
        Self { world, held, occluders: world.occluders(held) }
    }

    /// The nearest hit of one of the path's rays.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.world.intersect_held(ray, f32::INFINITY, self.held)
    }

    /// One sample of `light` at `hit` (drawn from `u`): what `shade` makes of
    /// it, when `shade` finds it can matter (Some) and nothing blocks it. The
    /// shadow ray is counted only when it is traced.
    #[inline]
    pub fn light_sample<T>(
        &self,
        light: &LightSource,
        hit: &Hit,
        u: Vec2,
        counters: &mut Counters,
        shade: impl FnOnce(&LightSample) -> Option<T>,
    ) -> Option<(LightSample, T)> {
        let (sample, value) = self.unshadowed_light_sample(light, hit, u, counters, shade)?;
        (!self.occluders.blocks(&sample)).then_some((sample, value))
    }

    /// `light_sample` short of its shadow ray, counted as traced: for a
    /// caller that traces it later (`Shadow::toward` the sample, with this
    /// path's `held`).
    #[inline]
    pub fn unshadowed_light_sample<T>(
        &self,
        light: &LightSource,
        hit: &Hit,
        u: Vec2,
        counters: &mut Counters,
        shade: impl FnOnce(&LightSample) -> Option<T>,
    ) -> Option<(LightSample, T)> {
        let sample = light.sample(&hit.surface, u)?;
        let value = shade(&sample)?;
        counters.rays += 1;
        Some((sample, value))
    }

    /// Direct light from one light chosen uniformly, weighted against BSDF
    /// sampling by the power heuristic (delta lights at full weight), times
    /// `throughput`: path tracing's estimate.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn one_light(
        &self,
        hit: &Hit,
        wo: Vec3,
        facing: Vec3,
        bsdf: &Bsdf,
        throughput: Rgb,
        sampler: &mut Sampler,
        counters: &mut Counters,
    ) -> Rgb {
        let lights = &self.world.lights;
        let count = lights.len();
        if count == 0 {
            return Rgb::ZERO;
        }
        // One light needs no draw to choose it
        let pick = match count {
            1 => 0,
            _ => ((sampler.next_f32() * count as f32) as usize).min(count - 1),
        };
        let pick_pdf = 1.0 / count as f32;
        let light = &lights[pick];
        let shade = |sample: &LightSample| Some(bsdf.eval(wo, sample.wi, facing)).filter(|f| *f != Rgb::ZERO);
        let Some((sample, f)) = self.light_sample(light, hit, sampler.next_2d(), counters, shade) else {
            return Rgb::ZERO;
        };
        let weight = if light.is_delta() {
            1.0
        } else {
            power_heuristic(pick_pdf * sample.pdf, bsdf.pdf(wo, sample.wi, facing))
        };
        throughput * f * sample.value * (sample.wi.dot(facing) * weight / pick_pdf)
    }

    /// Direct light from one sample of every light, unweighted: photon
    /// mapping's and SPPM's estimate (less noise than one light a sample, and
    /// their cost is elsewhere).
    pub fn every_light(
        &self,
        hit: &Hit,
        wo: Vec3,
        facing: Vec3,
        bsdf: &Bsdf,
        sampler: &mut Sampler,
        counters: &mut Counters,
    ) -> Rgb {
        let mut radiance = Rgb::ZERO;
        for light in &self.world.lights {
            if let Some((sample, term)) = self.lit_term(light, hit, wo, facing, bsdf, sampler.next_2d(), counters) {
                if !self.occluders.blocks(&sample) {
                    radiance += term;
                }
            }
        }
        radiance
    }

    /// `every_light` with its shadow rays asked of `shadows`: each light's
    /// term and its ray, into `terms`, for `lit_sum` once they are traced.
    #[allow(clippy::too_many_arguments)]
    pub fn every_light_later(
        &self,
        hit: &Hit,
        wo: Vec3,
        facing: Vec3,
        bsdf: &Bsdf,
        sampler: &mut Sampler,
        counters: &mut Counters,
        shadows: &mut ShadowBatch,
        terms: &mut Vec<(Rgb, u32)>,
    ) {
        for light in &self.world.lights {
            if let Some((sample, term)) = self.lit_term(light, hit, wo, facing, bsdf, sampler.next_2d(), counters) {
                terms.push((term, shadows.push(Shadow::toward(&sample, self.held))));
            }
        }
    }

    /// One light's unweighted term, f·L·cos, where it can matter; its
    /// shadow ray is counted, not traced.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn lit_term(
        &self,
        light: &LightSource,
        hit: &Hit,
        wo: Vec3,
        facing: Vec3,
        bsdf: &Bsdf,
        u: Vec2,
        counters: &mut Counters,
    ) -> Option<(LightSample, Rgb)> {
        let shade = |sample: &LightSample| Some(bsdf.eval(wo, sample.wi, facing)).filter(|f| *f != Rgb::ZERO);
        let (sample, f) = self.unshadowed_light_sample(light, hit, u, counters, shade)?;
        let term = f * sample.value * sample.wi.dot(facing);
        Some((sample, term))
    }
}

/// The direct light of `every_light_later`'s terms, in order, those that
/// `shadows` (traced) lets through: `every_light`, bit for bit.
pub fn lit_sum(terms: &[(Rgb, u32)], shadows: &ShadowBatch) -> Rgb {
    let mut radiance = Rgb::ZERO;
    for &(term, shadow) in terms {
        if !shadows.blocked(shadow) {
            radiance += term;
        }
    }
    radiance
}
