//! What the surfaces at eight hits are, and the directions they scatter
//! into: `Bsdf::sample` in the lanes, for camera paths (radiance) and
//! photons (importance) alike, each material drawing from the lanes'
//! streams only the numbers the scalar code draws.

use std::f32::consts::FRAC_1_PI;

use super::glossy::GlossyLanes;
use super::surface_table::SurfaceTable;
use super::{EMITTER, GLASS, LAMBERT, MIRROR};
use crate::geometry::{frame_from_z, to_world};
use crate::render::world::bsdf::{reflect_of, refraction_of, Refraction, Transport};
use crate::render::world::lanes::{Index8, Rng8, F8, M8, V8};
use crate::render::world::sampling::cosine_hemisphere_of;

/// The surfaces of the lanes of `alive`, by material.
pub(crate) struct LaneSurfaces<'a> {
    table: &'a SurfaceTable,
    /// Each lane's shape.
    index: Index8,
    pub(crate) lambert: M8,
    pub(crate) mirror: M8,
    pub(crate) glass: M8,
    /// Emitters, and surfaces that neither reflect nor emit.
    pub(crate) emissive: M8,
    pub(super) glossy: GlossyLanes,
    /// Albedo, tint, radiance or a glossy surface's diffuse part.
    pub(super) color: V8,
}

/// Directions drawn at eight hits (`Bsdf::sample`).
pub(crate) struct Scattered {
    /// The lanes that scattered (the others' paths end).
    pub(crate) go: M8,
    /// Lanes whose draws are deltas (on mirrors and glass).
    pub(crate) delta: M8,
    pub(crate) wi: V8,
    /// f · cos / pdf.
    pub(crate) weight: V8,
    pub(crate) pdf: F8,
}

impl<'a> LaneSurfaces<'a> {
    /// `index` names each lane's shape in `table` (lanes outside `alive`
    /// read any).
    #[inline(always)]
    pub(super) fn new(table: &'a SurfaceTable, index: Index8, alive: M8) -> Self {
        let code = table.kind.get(index);
        let kind = |k: f32| code.eq(F8::splat(k)).and(alive);
        let color = table.color.get(index);
        LaneSurfaces {
            lambert: kind(LAMBERT),
            mirror: kind(MIRROR),
            glass: kind(GLASS),
            emissive: kind(EMITTER),
            glossy: GlossyLanes::new(table, index, code, color, alive),
            color,
            table,
            index,
        }
    }

    /// Only the lanes of `lanes` left (the others' surfaces scatter nothing).
    #[inline(always)]
    pub(super) fn keep(&mut self, lanes: M8) {
        self.lambert = self.lambert.and(lanes);
        self.mirror = self.mirror.and(lanes);
        self.glass = self.glass.and(lanes);
        self.emissive = self.emissive.and(lanes);
        self.glossy.keep(lanes);
    }

    /// `Bsdf::is_specular`: mirrors, glass, and what reflects nothing.
    #[inline(always)]
    pub(crate) fn specular(&self) -> M8 {
        self.mirror.or(self.glass).or(self.emissive)
    }

    /// `Bsdf::sample` at each lane's surface, from the direction `wo`
    /// toward where the path came from, the geometric `normal` and it
    /// turned to `wo`'s side (`facing`).
    #[inline(always)]
    pub(crate) fn scatter(&self, rng: &mut Rng8, wo: V8, normal: V8, facing: V8, transport: Transport) -> Scattered {
        let zero = F8::splat(0.0);
        let mut wi = reflect_of(wo, facing);
        let mut weight = self.color;
        let mut pdf = F8::splat(1.0);
        let mut go = self.mirror;
        if self.lambert.any() {
            let (u0, u1) = rng.next_2d(self.lambert);
            let w = to_world(frame_from_z(facing), cosine_hemisphere_of(u0, u1));
            let cos = w.dot(facing);
            let ok = self.lambert.and(cos.gt(zero));
            wi = ok.select_v(w, wi);
            pdf = ok.select(cos.max(zero) * FRAC_1_PI, pdf);
            go = go.or(ok);
        }
        let glossy = self.glossy.mask();
        if glossy.any() {
            let u_lobe = rng.next_f32(glossy);
            let u = rng.next_2d(glossy);
            let (ok, w, f_cos_over_pdf, p) = self.glossy.sample(wo, facing, u_lobe, u);
            wi = ok.select_v(w, wi);
            weight = ok.select_v(f_cos_over_pdf, weight);
            pdf = ok.select(p, pdf);
            go = go.or(ok);
        }
        if self.glass.any() {
            let ior = self.table.ior.get(self.index);
            let entering = wo.dot(normal).gt(zero);
            let eta_i = entering.select(F8::splat(1.0), ior);
            let eta_t = entering.select(ior, F8::splat(1.0));
            let Refraction { fresnel, direction: refracted, eta, total } = refraction_of(wo, facing, eta_i, eta_t);
            let u_lobe = rng.next_f32(self.glass.and_not(total));
            let through = self.glass.and_not(total).and(u_lobe.ge(fresnel));
            let bounced = self.glass.and_not(through);
            // Radiance is compressed by η² entering a denser medium; power is not
            let carried = match transport {
                Transport::Radiance => self.color * (eta * eta),
                Transport::Importance => self.color,
            };
            wi = through.select_v(refracted, wi);
            weight = through.select_v(carried, weight);
            pdf = through.select(1.0 - fresnel, bounced.select(fresnel, pdf));
            go = go.or(self.glass);
        }
        Scattered { go, delta: self.specular(), wi, weight, pdf }
    }
}
