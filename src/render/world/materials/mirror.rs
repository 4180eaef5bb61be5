//! A perfect mirror: all light leaves in the mirror direction, tinted.

use glam::Vec3;

use super::optics::reflect_of;
use super::{At, Brought, Draws, Sampled, Scatter, Shares, Thesis, Transport};
use crate::geometry::real::{Real, V3};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror<R: Real> {
    pub tint: V3<R>,
}

impl<R: Real> Scatter<R> for Mirror<R> {
    const DELTA: bool = true;

    #[inline(always)]
    fn reflectance(&self) -> V3<R> {
        self.tint
    }

    #[inline(always)]
    fn eval_pdf(&self, _wo: V3<R>, _wi: V3<R>, _n: V3<R>) -> (V3<R>, R) {
        (V3::splat(Vec3::ZERO), R::splat(0.0))
    }

    #[inline(always)]
    fn sample(&self, live: R::Mask, at: &At<R>, _draws: &mut impl Draws<R>, _transport: Transport) -> Sampled<R> {
        let At { wo, facing, .. } = *at;
        Sampled { go: live, wi: reflect_of(wo, facing), weight: self.tint, pdf: R::splat(1.0) }
    }
}

/// The thesis' mirror: the reflected ray's light, tinted; lights and the
/// ambient light do not shade it.
impl Thesis for Mirror<f32> {
    const LIT: bool = false;

    fn shares(&self, _at: &At<f32>) -> Shares {
        Shares { reflected: Rgb::from(self.tint).max_element(), refracted: None }
    }

    fn combine(&self, _ambient: Rgb, _local: Rgb, brought: Brought, _at: &At<f32>) -> Rgb {
        match brought.reflected {
            Some(reflected) => Rgb::from(self.tint) * reflected,
            None => Rgb::ZERO,
        }
    }
}
