//! Phong and Blinn–Phong in eight lanes: `Bsdf`'s evaluation, pdf and
//! sampling for the lanes whose surface is glossy, on the functions the
//! scalar `Bsdf` calls.

use glam::Vec3;

use super::surface_table::SurfaceTable;
use super::{BLINN_PHONG, PHONG};
use crate::geometry::{frame_from_z, to_world};
use crate::render::world::bsdf::{blinn_phong_of, phong_of, reflect_of};
use crate::render::world::lanes::{Index8, F8, M8, V8};
use crate::render::world::sampling::{cosine_hemisphere_of, power_cosine_of};

/// The glossy lanes of a bounce and their surfaces' lobes.
pub(super) struct GlossyLanes {
    phong: M8,
    blinn_phong: M8,
    kd: V8,
    ks: V8,
    exponent: F8,
    diffuse_probability: F8,
    normalisation: F8,
}

impl GlossyLanes {
    /// The lanes of `alive` on a Phong or Blinn–Phong surface; `color` is
    /// each lane's surface colour (the diffuse lobe's).
    #[inline(always)]
    pub(super) fn new(table: &SurfaceTable, index: Index8, code: F8, color: V8, alive: M8) -> Self {
        let phong = code.eq(F8::splat(PHONG)).and(alive);
        let blinn_phong = code.eq(F8::splat(BLINN_PHONG)).and(alive);
        // The lobes' parameters gathered only where a lane is glossy: a
        // scene without a glossy surface would gather them at every bounce
        // for nothing
        let (ks, exponent, diffuse_probability, normalisation) = match phong.or(blinn_phong).any() {
            true => (
                table.specular.get(index),
                table.exponent.get(index),
                table.diffuse_probability.get(index),
                table.normalisation.get(index),
            ),
            false => (V8::splat(Vec3::ZERO), F8::splat(0.0), F8::splat(0.0), F8::splat(0.0)),
        };
        GlossyLanes { phong, blinn_phong, kd: color, ks, exponent, diffuse_probability, normalisation }
    }

    #[inline(always)]
    pub(super) fn mask(&self) -> M8 {
        self.phong.or(self.blinn_phong)
    }

    /// Only the lanes of `lanes` left.
    #[inline(always)]
    pub(super) fn keep(&mut self, lanes: M8) {
        self.phong = self.phong.and(lanes);
        self.blinn_phong = self.blinn_phong.and(lanes);
    }

    /// `Bsdf::eval_pdf` for `wo` and `wi` above the surface of normal `n`.
    #[inline(always)]
    pub(super) fn f_pdf(&self, wo: V8, wi: V8, n: V8) -> (V8, F8) {
        let (mut f, mut pdf) = (V8::splat(Vec3::ZERO), F8::splat(0.0));
        let pd = self.diffuse_probability;
        if self.phong.any() {
            let (phong_f, phong_pdf) = phong_of(self.kd, self.ks, self.exponent, pd, wo, wi, n);
            (f, pdf) = (self.phong.select_v(phong_f, f), self.phong.select(phong_pdf, pdf));
        }
        if self.blinn_phong.any() {
            let (blinn_f, blinn_pdf) =
                blinn_phong_of(self.kd, self.ks, self.exponent, self.normalisation, pd, wo, wi, n);
            (f, pdf) = (self.blinn_phong.select_v(blinn_f, f), self.blinn_phong.select(blinn_pdf, pdf));
        }
        (f, pdf)
    }

    /// `Bsdf::sample` from the lobe draw `u_lobe` and the direction draw
    /// (u0, u1): which lanes scattered, with their direction, weight
    /// (f·cos/pdf) and pdf.
    #[inline(always)]
    pub(super) fn sample(&self, wo: V8, facing: V8, u_lobe: F8, (u0, u1): (F8, F8)) -> (M8, V8, V8, F8) {
        let zero = F8::splat(0.0);
        let diffuse = to_world(frame_from_z(facing), cosine_hemisphere_of(u0, u1));
        let lobe = power_cosine_of(u0, u1, self.exponent);
        let about_mirror = to_world(frame_from_z(reflect_of(wo, facing)), lobe);
        let about_half = reflect_of(wo, to_world(frame_from_z(facing), lobe));
        let specular = self.phong.select_v(about_mirror, about_half);
        let wi = u_lobe.lt(self.diffuse_probability).select_v(diffuse, specular);
        // The pdf is 0 below the surface, and a direction of pdf 0 ends the path
        let below = wi.dot(facing).le(zero).or(wo.dot(facing).le(zero));
        let (f, pdf) = self.f_pdf(wo, wi, facing);
        let pdf = below.select(zero, pdf);
        let scattered = self.mask().and_not(pdf.le(zero));
        let weight = f * (wi.dot(facing) / pdf);
        (scattered, wi, weight, pdf)
    }
}
