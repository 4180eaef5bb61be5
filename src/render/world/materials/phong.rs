//! Phong's model, normalised: the thesis' diffuse part plus
//! (n + 2)/2π · cosⁿ α about the mirror direction, sampled by the diffuse
//! part or cosⁿ α in proportion to their luminance.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::glossy::{diffuse_probability, glossy_of, sampled, thesis_combine, thesis_local};
use super::optics::{reflect, reflect_of};
use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::faults::{self, Fault};
use crate::geometry::real::{Real, V3};
use crate::geometry::{frame_from_z, to_world};
use crate::render::world::sampling::{cosine_hemisphere_of, power_cosine_of};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong<R: Real> {
    pub kd: V3<R>,
    pub ks: V3<R>,
    pub exponent: R,
    /// The chance of sampling the diffuse part (`glossy::diffuse_probability`).
    pub diffuse_probability: R,
}

impl Phong<f32> {
    pub fn new(kd: Rgb, ks: Rgb, exponent: f32) -> Self {
        Phong { kd: kd.into(), ks: ks.into(), exponent, diffuse_probability: diffuse_probability(kd, ks) }
    }
}

impl<R: Real> Scatter<R> for Phong<R> {
    const DELTA: bool = false;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        self.kd + self.ks
    }

    #[inline(always)]
    fn eval_pdf(&self, wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R) {
        let cos_alpha = reflect_of(wo, n).dot(wi);
        let lobe_scale = (self.exponent + 2.0) * 0.5 * FRAC_1_PI;
        let lobe_scale = if faults::active(Fault::PhongLobeDim) { lobe_scale * 0.97 } else { lobe_scale };
        let pd = self.diffuse_probability;
        glossy_of(self.kd, self.ks, self.exponent, cos_alpha, lobe_scale, R::splat(1.0), pd, wi.dot(n))
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { wo, facing, .. } = *at;
        let u_lobe = draws.next_1d(live);
        let (u0, u1) = draws.next_2d(live);
        let diffuse = to_world(frame_from_z(facing), cosine_hemisphere_of(u0, u1));
        let about_mirror = to_world(frame_from_z(reflect_of(wo, facing)), power_cosine_of(u0, u1, self.exponent));
        let wi = V3::select(u_lobe.lt(self.diffuse_probability), diffuse, about_mirror);
        sampled(live, wo, wi, facing, self.eval_pdf(wo, wi, facing))
    }
}

/// The thesis' model: `kd·cos + ks·(r·v)^α` toward a light, `ka` of the ambient
/// light, and the mirror ray's light scaled by `ks`.
impl Thesis for Phong<f32> {
    const LIT: bool = true;

    fn local(&self, at: &At<f32>, wi: Vec3, cos: f32) -> Rgb {
        let (wo, facing): (Vec3, Vec3) = (at.wo.into(), at.facing.into());
        thesis_local(self.kd.into(), self.ks.into(), self.exponent, cos, || reflect(wi, facing).dot(wo))
    }

    fn shares(&self, _at: &At<f32>) -> Shares {
        Shares { reflected: Rgb::from(self.ks).max_element(), refracted: None }
    }

    fn combine(&self, ambient: Rgb, local: Rgb, brought: Brought, _at: &At<f32>) -> Rgb {
        thesis_combine(self.ks.into(), ambient, local, brought.reflected)
    }
}
