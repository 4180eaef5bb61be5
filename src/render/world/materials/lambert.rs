//! Lambert's diffuse surface: f = albedo/π, sampled by the cosine.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::geometry::real::{Mask, Real, V3};
use crate::geometry::{frame_from_z, to_world};
use crate::render::world::sampling::{cosine_hemisphere_of, cosine_hemisphere_pdf_of};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert<R: Real> {
    pub albedo: V3<R>,
}

impl<R: Real> Scatter<R> for Lambert<R> {
    const DELTA: bool = false;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        self.albedo
    }

    #[inline(always)]
    fn eval_pdf(&self, _wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R) {
        (self.albedo * R::splat(FRAC_1_PI), cosine_hemisphere_pdf_of(wi.dot(n)))
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { facing, .. } = *at;
        let (u0, u1) = draws.next_2d(live);
        let wi = to_world(frame_from_z(facing), cosine_hemisphere_of(u0, u1));
        let cos = wi.dot(facing);
        Sampled { go: live.and(cos.gt(R::splat(0.0))), wi, weight: self.albedo, pdf: cosine_hemisphere_pdf_of(cos) }
    }
}

/// The thesis' diffuse model: `kd·cos` toward a light, `kd` of the ambient.
impl Thesis for Lambert<f32> {
    const LIT: bool = true;

    fn local(&self, _at: &At<f32>, _wi: Vec3, cos: f32) -> Rgb {
        Rgb::from(self.albedo) * cos
    }

    fn shares(&self, _at: &At<f32>) -> Shares {
        Shares::NONE
    }

    fn combine(&self, ambient: Rgb, local: Rgb, _brought: Brought, _at: &At<f32>) -> Rgb {
        ambient + local
    }
}
