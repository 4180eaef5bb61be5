//! Smooth glass: Fresnel's share reflected, the rest refracted, one of
//! the two chosen by that share.

use glam::Vec3;

use super::optics::{reflect_of, refract, refraction_of, Refraction};
use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::geometry::real::{Mask, Real, V3};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glass<R: Real> {
    pub ior: R,
    pub tint: V3<R>,
}

impl<R: Real> Scatter<R> for Glass<R> {
    const DELTA: bool = true;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        self.tint
    }

    #[inline(always)]
    fn eval_pdf(&self, _wo: V3<R>, _wi: V3<R>, _n: V3<R>) -> (V3<R>, R) {
        (V3::splat(Vec3::ZERO), R::splat(0.0))
    }

    /// The geometric `normal` tells entering from leaving; the sample's pdf
    /// is the chance of the lobe chosen (what a bidirectional method's
    /// reverse density reads).
    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, transport: Transport) -> Sampled<R> {
        let At { wo, normal, facing, .. } = *at;
        let one = R::splat(1.0);
        let entering = wo.dot(normal).gt(R::splat(0.0));
        let (eta_i, eta_t) = (R::select(entering, one, self.ior), R::select(entering, self.ior, one));
        let Refraction { fresnel, direction, eta, total } = refraction_of(wo, facing, eta_i, eta_t);
        // A lobe to choose only where refraction is possible
        let can_refract = live.and_not(total);
        let through = can_refract.and(draws.next_1d(can_refract).ge(fresnel));
        // Radiance is compressed by η² entering a denser medium; power is not
        let carried = match transport {
            Transport::Radiance => self.tint * (eta * eta),
            Transport::Importance => self.tint,
        };
        Sampled {
            go: live,
            wi: V3::select(through, direction, reflect_of(wo, facing)),
            weight: V3::select(through, carried, self.tint),
            pdf: R::select(through, one - fresnel, fresnel),
        }
    }
}

impl Glass<f32> {
    /// Fresnel's reflectance, the refracted direction (None under total
    /// internal reflection) and η_i/η_t, entering or leaving by the normal.
    fn refraction(&self, at: &At<f32>) -> (f32, Option<Vec3>, f32) {
        let (wo, n, facing): (Vec3, Vec3, Vec3) = (at.wo.into(), at.normal.into(), at.facing.into());
        let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, self.ior) } else { (self.ior, 1.0) };
        refract(wo, facing, eta_i, eta_t)
    }
}

/// The thesis' glass: Fresnel's shares of a reflected and a refracted ray,
/// both traced; lights and the ambient light do not shade it.
impl Thesis for Glass<f32> {
    const LIT: bool = false;

    fn shares(&self, at: &At<f32>) -> Shares {
        let (fresnel, refracted, _) = self.refraction(at);
        Shares { reflected: fresnel, refracted: refracted.map(|wt| (wt, 1.0 - fresnel)) }
    }

    fn combine(&self, _ambient: Rgb, _local: Rgb, brought: Brought, at: &At<f32>) -> Rgb {
        let (fresnel, _, eta) = self.refraction(at);
        let Brought { reflected, refracted } = brought;
        let mut c = Rgb::ZERO;
        if let Some(reflected) = reflected {
            c += fresnel * reflected;
        }
        if let Some(refracted) = refracted {
            // Radiance is compressed by η² crossing into the denser side
            c += (1.0 - fresnel) * eta * eta * refracted;
        }
        Rgb::from(self.tint) * c
    }
}
