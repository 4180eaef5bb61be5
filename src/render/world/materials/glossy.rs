//! What Phong and Blinn–Phong share: a diffuse part plus a lobe cosⁿ about
//! a direction, the lobe chosen by its share of the luminance.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::Sampled;
use crate::geometry::pow;
use crate::geometry::real::{Mask, Real, V3};
use crate::render::world::sampling::cosine_hemisphere_pdf_of;
use crate::scene::Rgb;

#[inline]
fn luminance(c: Rgb) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Probability of choosing the diffuse part of a Phong-like BRDF: its
/// share of the luminance (Rec. 709).
#[inline]
pub fn diffuse_probability(kd: Rgb, ks: Rgb) -> f32 {
    let (d, s) = (luminance(kd), luminance(ks));
    if d + s > 0.0 {
        d / (d + s)
    } else {
        1.0
    }
}

/// A glossy lobe's f and the pdf of its sampling, from one power: the
/// lobe's cosine `cos` (to the mirror direction for Phong, of the half
/// vector for Blinn–Phong) raised to `exponent`; the lobe is scaled by
/// `lobe_scale`, the lobe's pdf divided by `pdf_divisor`, and the diffuse
/// part taken with probability `pd`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn glossy_of<R: Real>(
    kd: V3<R>,
    ks: V3<R>,
    exponent: R,
    cos: R,
    lobe_scale: R,
    pdf_divisor: R,
    pd: R,
    cos_wi: R,
) -> (V3<R>, R) {
    let zero = R::splat(0.0);
    let power = cos.max(zero).powf(exponent);
    let lobe = ks * (lobe_scale * power);
    let specular = R::select(cos.le(zero), zero, (exponent + 1.0) * 0.5 * FRAC_1_PI * power) / pdf_divisor;
    (kd * R::splat(FRAC_1_PI) + lobe, pd * cosine_hemisphere_pdf_of(cos_wi) + (R::splat(1.0) - pd) * specular)
}

/// A glossy material's sample in the lanes of `live`, its direction `wi`
/// chosen and `(f, pdf)` its `eval_pdf`: a direction below the surface
/// has pdf 0 and ends the path.
#[inline(always)]
pub(super) fn sampled<R: Real>(live: R::Mask, wo: V3<R>, wi: V3<R>, facing: V3<R>, (f, pdf): (V3<R>, R)) -> Sampled<R> {
    let zero = R::splat(0.0);
    let below = wi.dot(facing).le(zero).or(wo.dot(facing).le(zero));
    let pdf = R::select(below, zero, pdf);
    Sampled { go: live.and_not(pdf.le(zero)), wi, weight: f * (wi.dot(facing) / pdf), pdf }
}

/// The thesis' local model of a glossy surface: `kd·cos + ks·highlight^α`,
/// the highlight's cosine asked only where there is a highlight.
#[inline]
pub(super) fn thesis_local(kd: Rgb, ks: Rgb, exponent: f32, cos: f32, highlight: impl FnOnce() -> f32) -> Rgb {
    let mut c = kd * cos;
    if ks != Rgb::ZERO {
        c += ks * pow::powf(highlight().max(0.0), exponent);
    }
    c
}

/// The thesis' glossy combination: the ambient light and the local model,
/// and the mirror ray's light scaled by the surface's reflectivity `ks`.
#[inline]
pub(super) fn thesis_combine(ks: Rgb, ambient: Rgb, local: Rgb, reflected: Option<Rgb>) -> Rgb {
    let mut c = ambient + local;
    if let Some(reflected) = reflected {
        c += ks * reflected;
    }
    c
}
