//! What a surface does to light. Each material is written once, in its own
//! file (`lambert`, `phong`, `blinn_phong`, `mirror`, `glass`,
//! `conductor`; the rough ones made of `microfacet`'s GGX), as a type
//! generic over `Real` implementing `Scatter`: the scalar code reaches it
//! through `Bsdf`, the closed list every algorithm dispatches through, and
//! the eight lanes through `lanes::LaneSurfaces`, which runs each material
//! present among eight hits on the lanes that hold it (pbrt-v4's tagged
//! dispatch and its wavefront loop over material types). Directions are
//! world-space unit vectors pointing away from the surface.

/// `$body` with `$m` bound to the material of each variant that scatters,
/// `$black` for `Bsdf::Black`.
macro_rules! each_material {
    ($bsdf:expr, $m:ident => $body:expr, black => $black:expr) => {
        match $bsdf {
            Bsdf::Lambert($m) => $body,
            Bsdf::Phong($m) => $body,
            Bsdf::BlinnPhong($m) => $body,
            Bsdf::Mirror($m) => $body,
            Bsdf::Glass($m) => $body,
            Bsdf::RoughConductor($m) => $body,
            Bsdf::SmoothConductor($m) => $body,
            Bsdf::Black => $black,
        }
    };
}

mod blinn_phong;
mod conductor;
mod glass;
mod glossy;
mod lambert;
pub(crate) mod lanes;
pub mod microfacet;
mod mirror;
mod optics;
mod phong;
#[cfg(test)]
mod tests;
mod thesis;

use glam::Vec3;

pub use blinn_phong::BlinnPhong;
pub use conductor::{RoughConductor, SmoothConductor};
pub use glass::Glass;
pub use lambert::Lambert;
pub use mirror::Mirror;
pub use optics::{fresnel_conductor_of, fresnel_dielectric, reflect, reflect_of, refract, refraction_of, Refraction};
pub use phong::Phong;
pub use thesis::{Brought, Shares, Thesis};

use crate::geometry::real::{Real, V3};
use crate::render::world::rng::Sampler;
use crate::scene::{MaterialModel, Metal, Rgb, SMOOTH_ALPHA};

/// What a path carries through refraction: camera paths carry radiance, which
/// is compressed by η² entering a denser medium; photons carry power, which is not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    Radiance,
    Importance,
}

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// f · |cos θi| / pdf: what the path throughput is multiplied by.
    pub weight: Rgb,
    pub pdf: f32,
    pub delta: bool,
}

/// The uniform numbers a material draws, at one hit or eight: only the
/// lanes of `lanes` draw, the others' streams are left as they are.
pub trait Draws<R: Real> {
    fn next_1d(&mut self, lanes: R::Mask) -> R;
    fn next_2d(&mut self, lanes: R::Mask) -> (R, R);
}

impl Draws<f32> for Sampler {
    #[inline(always)]
    fn next_1d(&mut self, lanes: bool) -> f32 {
        if lanes {
            self.next_f32()
        } else {
            0.0
        }
    }

    #[inline(always)]
    fn next_2d(&mut self, lanes: bool) -> (f32, f32) {
        if lanes {
            let u = Sampler::next_2d(self);
            (u.x, u.y)
        } else {
            (0.0, 0.0)
        }
    }
}

/// A direction drawn by a material, at one hit or eight.
#[derive(Clone, Copy, Debug)]
pub struct Sampled<R: Real> {
    /// Where a direction was drawn (elsewhere the path ends).
    pub go: R::Mask,
    pub wi: V3<R>,
    /// f · |cos θi| / pdf.
    pub weight: V3<R>,
    pub pdf: R,
}

/// Where a material scatters, at one hit or eight: the direction `wo`
/// toward where the path came from, the geometric `normal` (any side) and
/// it turned to `wo`'s side (`facing`).
#[derive(Clone, Copy, Debug)]
pub struct At<R: Real> {
    pub wo: V3<R>,
    pub normal: V3<R>,
    pub facing: V3<R>,
}

impl At<f32> {
    pub fn new(wo: Vec3, normal: Vec3) -> Self {
        let facing = if wo.dot(normal) < 0.0 { -normal } else { normal };
        At { wo: wo.into(), normal: normal.into(), facing: facing.into() }
    }
}

/// One material's scattering, at one hit (`R` = f32) or eight.
pub trait Scatter<R: Real> {
    /// Only delta lobes: no light sampling, no photon storage.
    const DELTA: bool;

    /// The share of light it sends on at most, per channel.
    fn reflectance(&self) -> V3<R>;

    /// f(wo, wi) and the solid-angle pdf of `sample` choosing `wi`, for
    /// `wo` and `wi` above the surface of normal `n` (zero for deltas).
    fn eval_pdf(&self, wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R);

    /// Draws an incoming direction in the lanes of `live`, drawing only
    /// the numbers it uses.
    fn sample(&self, live: R::Mask, at: &At<R>, draws: &mut impl Draws<R>, transport: Transport) -> Sampled<R>;
}

/// A surface's scattering at one hit: every material, one variant each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    Lambert(Lambert<f32>),
    Phong(Phong<f32>),
    BlinnPhong(BlinnPhong<f32>),
    Mirror(Mirror<f32>),
    Glass(Glass<f32>),
    RoughConductor(RoughConductor<f32>),
    SmoothConductor(SmoothConductor<f32>),
    /// Emitters reflect nothing.
    Black,
}

#[inline(always)]
fn is_delta<M: Scatter<f32>>(_: &M) -> bool {
    M::DELTA
}

#[inline(always)]
fn sample_one<M: Scatter<f32>>(
    material: &M,
    at: &At<f32>,
    sampler: &mut Sampler,
    transport: Transport,
) -> Option<BsdfSample> {
    let s = material.sample(true, at, sampler, transport);
    s.go.then(|| BsdfSample { wi: s.wi.into(), weight: s.weight.into(), pdf: s.pdf, delta: M::DELTA })
}

impl Bsdf {
    #[inline]
    pub fn new(material: &MaterialModel) -> Self {
        match *material {
            MaterialModel::Lambert { albedo } => Bsdf::lambert(albedo),
            MaterialModel::Phong { kd, ks, shininess, .. } => Bsdf::phong(kd, ks, shininess),
            MaterialModel::BlinnPhong { kd, ks, shininess, .. } => Bsdf::blinn_phong(kd, ks, shininess),
            MaterialModel::Mirror { tint } => Bsdf::mirror(tint),
            MaterialModel::Glass { ior, tint } => Bsdf::glass(ior, tint),
            MaterialModel::Conductor { metal, alpha_u, alpha_v } => Bsdf::conductor(metal, alpha_u, alpha_v),
            MaterialModel::Emissive { .. } => Bsdf::Black,
        }
    }

    pub fn lambert(albedo: Rgb) -> Self {
        Bsdf::Lambert(Lambert { albedo: albedo.into() })
    }

    pub fn phong(kd: Rgb, ks: Rgb, exponent: f32) -> Self {
        Bsdf::Phong(Phong::new(kd, ks, exponent))
    }

    pub fn blinn_phong(kd: Rgb, ks: Rgb, exponent: f32) -> Self {
        Bsdf::BlinnPhong(BlinnPhong::new(kd, ks, exponent))
    }

    pub fn mirror(tint: Rgb) -> Self {
        Bsdf::Mirror(Mirror { tint: tint.into() })
    }

    pub fn glass(ior: f32, tint: Rgb) -> Self {
        Bsdf::Glass(Glass { ior, tint: tint.into() })
    }

    /// A metal of roughness α_u, α_v: polished below `SMOOTH_ALPHA` on both
    /// axes (`MaterialModel::is_specular`).
    pub fn conductor(metal: Metal, alpha_u: f32, alpha_v: f32) -> Self {
        let (eta, k) = metal.index();
        let (eta, k) = (eta.into(), k.into());
        if alpha_u.max(alpha_v) < SMOOTH_ALPHA {
            return Bsdf::SmoothConductor(SmoothConductor { eta, k });
        }
        // A lobe narrower than SMOOTH_ALPHA on one axis only is kept that wide
        let ggx = microfacet::Ggx { alpha_x: alpha_u.max(SMOOTH_ALPHA), alpha_y: alpha_v.max(SMOOTH_ALPHA) };
        Bsdf::RoughConductor(RoughConductor { eta, k, ggx })
    }

    /// Only delta lobes: no light sampling, no photon storage.
    #[inline]
    pub fn is_specular(&self) -> bool {
        each_material!(self, m => is_delta(m), black => true)
    }

    /// The chance a path goes on after this surface under Russian roulette,
    /// as bidirectional methods play it: the surface's largest reflectance
    /// (at most 1), the same whichever way the path runs, so a subpath's
    /// density read backwards holds it too.
    #[inline]
    pub fn continuation(&self) -> f32 {
        let reflectance = each_material!(self, m => m.reflectance().into(), black => Rgb::ZERO);
        reflectance.max_element().min(1.0)
    }

    /// f(wo, wi) for the non-delta part; `n` faces `wo`'s side.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Rgb {
        self.eval_pdf(wo, wi, n).0
    }

    /// `eval(wo, wi, n)` for every `wi` in front of `n` (`wi · n > 0`),
    /// where that is one value (Lambert's): a density estimate then looks it
    /// up once per point, not once per photon.
    #[inline]
    pub fn front_constant(&self, wo: Vec3, n: Vec3) -> Option<Rgb> {
        match self {
            Bsdf::Lambert(_) => Some(self.eval(wo, n, n)),
            _ => None,
        }
    }

    /// Solid-angle pdf of `sample` choosing `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, n: Vec3) -> f32 {
        self.eval_pdf(wo, wi, n).1
    }

    /// `eval` and `pdf` together: a glossy lobe's power serves both.
    /// Lambert's inline wherever it is asked (the bidirectional methods ask
    /// four times a connection: a call passed its vectors through memory),
    /// the others out of line.
    #[inline(always)]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3, n: Vec3) -> (Rgb, f32) {
        if wi.dot(n) <= 0.0 || wo.dot(n) <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        match self {
            Bsdf::Lambert(m) => lifted(m.eval_pdf(wo.into(), wi.into(), n.into())),
            _ => self.eval_pdf_out_of_line(wo, wi, n),
        }
    }

    /// `eval_pdf` of the other materials, with both directions above the surface.
    #[inline(never)]
    fn eval_pdf_out_of_line(&self, wo: Vec3, wi: Vec3, n: Vec3) -> (Rgb, f32) {
        let (wo, wi, n) = (wo.into(), wi.into(), n.into());
        each_material!(self, m => lifted(m.eval_pdf(wo, wi, n)), black => (Rgb::ZERO, 0.0))
    }

    /// Draw an incoming direction. `n` is the geometric normal (any side);
    /// opaque models flip it to `wo`'s side, glass uses it to tell entering
    /// from leaving. Each model draws from `sampler` only the numbers it uses.
    #[inline]
    pub fn sample(&self, wo: Vec3, n: Vec3, sampler: &mut Sampler, transport: Transport) -> Option<BsdfSample> {
        let at = At::new(wo, n);
        each_material!(self, m => sample_one(m, &at, sampler, transport), black => None)
    }
}

#[inline(always)]
fn lifted((f, pdf): (V3<f32>, f32)) -> (Rgb, f32) {
    (f.into(), pdf)
}
