//! Blinn–Phong: a diffuse part plus cosⁿ of the half vector, normalised
//! exactly (Giesen 2009), sampled by the diffuse part or a half vector
//! cosⁿ about the normal in proportion to their luminance.

use std::f32::consts::PI;

use glam::Vec3;

use super::glossy::{diffuse_probability, glossy_of, sampled, thesis_combine, thesis_local};
use super::optics::reflect_of;
use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::geometry::real::{Real, V3};
use crate::geometry::{frame_from_z, to_world};
use crate::render::world::sampling::{cosine_hemisphere_of, power_cosine_of};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong<R: Real> {
    pub kd: V3<R>,
    pub ks: V3<R>,
    pub exponent: R,
    /// The chance of sampling the diffuse part (`glossy::diffuse_probability`).
    pub diffuse_probability: R,
    /// `normalisation(exponent)`.
    pub normalisation: R,
}

/// Exact normalisation of the Blinn–Phong lobe at normal incidence
/// (Giesen 2009); the common (n + 8)/8π exceeds energy 1 for n > 4.
#[inline]
pub(crate) fn normalisation(exponent: f32) -> f32 {
    (exponent + 2.0) * (exponent + 4.0) / (8.0 * PI * ((-exponent * 0.5).exp2() + exponent))
}

impl BlinnPhong<f32> {
    pub fn new(kd: Rgb, ks: Rgb, exponent: f32) -> Self {
        BlinnPhong {
            kd: kd.into(),
            ks: ks.into(),
            exponent,
            diffuse_probability: diffuse_probability(kd, ks),
            normalisation: normalisation(exponent),
        }
    }
}

impl<R: Real> Scatter<R> for BlinnPhong<R> {
    const DELTA: bool = false;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        self.kd + self.ks
    }

    /// The pdf turns the half vector's density into wi's.
    #[inline(always)]
    fn eval_pdf(&self, wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R) {
        let h = (wo + wi).normalize();
        let (pd, cos_wi) = (self.diffuse_probability, wi.dot(n));
        glossy_of(self.kd, self.ks, self.exponent, n.dot(h), self.normalisation, wo.dot(h) * 4.0, pd, cos_wi)
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { wo, facing, .. } = *at;
        let u_lobe = draws.next_1d(live);
        let (u0, u1) = draws.next_2d(live);
        let frame = frame_from_z(facing);
        let diffuse = to_world(frame, cosine_hemisphere_of(u0, u1));
        let about_half = reflect_of(wo, to_world(frame, power_cosine_of(u0, u1, self.exponent)));
        let wi = V3::select(u_lobe.lt(self.diffuse_probability), diffuse, about_half);
        sampled(live, wo, wi, facing, self.eval_pdf(wo, wi, facing))
    }
}

/// The thesis' model: `kd·cos + ks·(n·h)^α` toward a light, `ka` of the ambient
/// light, and the mirror ray's light scaled by `ks`.
impl Thesis for BlinnPhong<f32> {
    const LIT: bool = true;

    fn local(&self, at: &At<f32>, wi: Vec3, cos: f32) -> Rgb {
        let (wo, facing): (Vec3, Vec3) = (at.wo.into(), at.facing.into());
        thesis_local(self.kd.into(), self.ks.into(), self.exponent, cos, || facing.dot((wi + wo).normalize()))
    }

    fn shares(&self, _at: &At<f32>) -> Shares {
        Shares { reflected: Rgb::from(self.ks).max_element(), refracted: None }
    }

    fn combine(&self, ambient: Rgb, local: Rgb, brought: Brought, _at: &At<f32>) -> Rgb {
        thesis_combine(self.ks.into(), ambient, local, brought.reflected)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Giesen's normalisation makes the Blinn–Phong lobe reflect all it
    /// receives at normal incidence: 2π ∫ N cosⁿ(θ/2) cos θ sin θ dθ = 1
    /// (the half vector lies halfway to the normal), by Simpson's rule in f64.
    #[test]
    fn blinn_phong_reflects_everything_at_normal_incidence() {
        for exponent in [0.5f32, 1.0, 4.0, 10.0, 100.0, 1000.0] {
            let normalisation = normalisation(exponent) as f64;
            let f = |theta: f64| normalisation * (theta / 2.0).cos().powf(exponent as f64) * theta.cos() * theta.sin();
            let steps = 20_000;
            let h = std::f64::consts::FRAC_PI_2 / steps as f64;
            let simpson: f64 = (0..=steps)
                .map(|i| f(i as f64 * h) * if i == 0 || i == steps { 1.0 } else { (2 + 2 * (i % 2)) as f64 })
                .sum();
            let albedo = 2.0 * std::f64::consts::PI * simpson * h / 3.0;
            assert!((albedo - 1.0).abs() < 1e-5, "exponent {exponent}: {albedo}");
        }
    }
}
