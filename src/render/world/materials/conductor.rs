//! Metals: Fresnel reflection of a conductor of complex index η + ik per
//! channel, on GGX microfacets (`RoughConductor`, Walter et al. 2007 with
//! Smith's separable masking, as Mitsuba's `roughconductor`) or on a
//! polished surface (`SmoothConductor`, a delta mirror whose colour is
//! Fresnel's). The rough lobe is sampled by the normals `wo` sees.

use glam::Vec3;

use super::glossy::sampled;
use super::microfacet::Ggx;
use super::optics::{fresnel_conductor_of, reflect_of};
use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::geometry::real::{Mask, Real, V3};
use crate::geometry::{frame_from_z, to_local, to_world};
use crate::scene::Rgb;

/// A rough metal. Its anisotropy follows the frame `frame_from_z` builds
/// about the normal: α_x along the frame's first axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor<R: Real> {
    pub eta: V3<R>,
    pub k: V3<R>,
    pub ggx: Ggx<R>,
}

/// A polished metal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothConductor<R: Real> {
    pub eta: V3<R>,
    pub k: V3<R>,
}

impl<R: Real> Scatter<R> for RoughConductor<R> {
    const DELTA: bool = false;

    /// Fresnel's reflectance reaches 1 at grazing angles.
    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        V3::splat(Vec3::ONE)
    }

    /// f = F(wo·h) D(h) G1(wo) G1(wi) / (4 cos θo cos θi), and the density
    /// of the visible normals' reflection, D_wo(h) / (4 wo·h) =
    /// G1(wo) D(h) / (4 cos θo).
    #[inline(always)]
    fn eval_pdf(&self, wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R) {
        let zero = R::splat(0.0);
        let frame = frame_from_z(n);
        let (o, i) = (to_local(frame, wo), to_local(frame, wi));
        let h = (o + i).normalize();
        let d = self.ggx.d(h);
        let g1_o = self.ggx.g1(o);
        let lobe = d * g1_o * self.ggx.g1(i) / (o.z * i.z * 4.0);
        let pdf = g1_o * d / (o.z * 4.0);
        let fresnel = fresnel_conductor_of(o.dot(h).min(R::splat(1.0)), self.eta, self.k);
        let below = o.z.le(zero).or(i.z.le(zero));
        (V3::select(below, V3::splat(Vec3::ZERO), fresnel * lobe), R::select(below, zero, pdf))
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { wo, facing, .. } = *at;
        let (u0, u1) = draws.next_2d(live);
        let frame = frame_from_z(facing);
        let h = self.ggx.sample_visible(to_local(frame, wo), u0, u1);
        let wi = reflect_of(wo, to_world(frame, h));
        sampled(live, wo, wi, facing, self.eval_pdf(wo, wi, facing))
    }
}

impl<R: Real> Scatter<R> for SmoothConductor<R> {
    const DELTA: bool = true;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        V3::splat(Vec3::ONE)
    }

    #[inline(always)]
    fn eval_pdf(&self, _wo: V3<R>, _wi: V3<R>, _n: V3<R>) -> (V3<R>, R) {
        (V3::splat(Vec3::ZERO), R::splat(0.0))
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, _draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { wo, facing, .. } = *at;
        let fresnel = fresnel_conductor_of(wo.dot(facing).min(R::splat(1.0)), self.eta, self.k);
        Sampled { go: live, wi: reflect_of(wo, facing), weight: fresnel, pdf: R::splat(1.0) }
    }
}

/// Whitted's view of a rough metal: its lobe toward each light (the
/// thesis' local model is the material's f·cos), the ambient light by its
/// colour at normal incidence, no rays spawned.
impl Thesis for RoughConductor<f32> {
    const LIT: bool = true;

    fn local(&self, at: &At<f32>, wi: Vec3, cos: f32) -> Rgb {
        Rgb::from(self.eval_pdf(at.wo, wi.into(), at.facing).0) * cos
    }

    fn shares(&self, _at: &At<f32>) -> Shares {
        Shares::NONE
    }

    fn combine(&self, ambient: Rgb, local: Rgb, _brought: Brought, _at: &At<f32>) -> Rgb {
        ambient + local
    }
}

/// Whitted's view of a polished metal: a mirror whose tint is Fresnel's.
impl Thesis for SmoothConductor<f32> {
    const LIT: bool = false;

    fn shares(&self, at: &At<f32>) -> Shares {
        Shares { reflected: Rgb::from(self.fresnel(at)).max_element(), refracted: None }
    }

    fn combine(&self, _ambient: Rgb, _local: Rgb, brought: Brought, at: &At<f32>) -> Rgb {
        brought.reflected.map_or(Rgb::ZERO, |reflected| Rgb::from(self.fresnel(at)) * reflected)
    }
}

impl SmoothConductor<f32> {
    fn fresnel(&self, at: &At<f32>) -> V3<f32> {
        fresnel_conductor_of(at.wo.dot(at.facing).min(1.0), self.eta, self.k)
    }
}
