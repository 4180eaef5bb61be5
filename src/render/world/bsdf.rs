//! Physically based scattering for the Monte Carlo algorithms: the thesis'
//! local models turned into energy-conserving BRDFs, plus mirror and glass.
//! Directions are world-space unit vectors pointing away from the surface.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::Vec3;

use crate::faults::{self, Fault};
use crate::geometry::real::{Real, V3};
use crate::geometry::Frame;
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::{
    cosine_hemisphere, cosine_hemisphere_pdf, cosine_hemisphere_pdf_of, power_cosine,
};
use crate::scene::{MaterialModel, Rgb};

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

#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    reflect_of(w.into(), n.into()).into()
}

/// `reflect` for one direction or several.
#[inline(always)]
pub fn reflect_of<R: Real>(w: V3<R>, n: V3<R>) -> V3<R> {
    n * (w.dot(n) * 2.0) - w
}

#[inline]
fn luminance(c: Rgb) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Unpolarised Fresnel reflectance of a dielectric interface.
#[inline(always)]
pub fn fresnel_dielectric<R: Real>(cos_i: R, cos_t: R, eta_i: R, eta_t: R) -> R {
    let parallel = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    let perpendicular = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    (parallel * parallel + perpendicular * perpendicular) * 0.5
}

/// Refraction of `wo` through a surface with normal `n` on `wo`'s side:
/// (Fresnel reflectance, refracted direction or None under total internal
/// reflection, η_i/η_t).
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta_i: f32, eta_t: f32) -> (f32, Option<Vec3>, f32) {
    let refraction = refraction_of(wo.into(), n.into(), eta_i, eta_t);
    let direction = (!refraction.total).then(|| refraction.direction.into());
    (refraction.fresnel, direction, refraction.eta)
}

/// What a dielectric does to `wo`, for one direction or several.
#[derive(Clone, Copy, Debug)]
pub struct Refraction<R: Real> {
    /// Fresnel reflectance (1 under total internal reflection).
    pub fresnel: R,
    /// The refracted direction (meaningless where `total`).
    pub direction: V3<R>,
    /// η_i/η_t.
    pub eta: R,
    /// Total internal reflection.
    pub total: R::Mask,
}

/// `refract` for one direction or several.
#[inline(always)]
pub fn refraction_of<R: Real>(wo: V3<R>, n: V3<R>, eta_i: R, eta_t: R) -> Refraction<R> {
    let eta = eta_i / eta_t;
    // clamp(0, 1), a NaN kept
    let cos_i = R::splat(1.0).min(R::splat(0.0).max(wo.dot(n)));
    let sin2_t = eta * eta * (R::splat(1.0) - cos_i * cos_i);
    let total = sin2_t.ge(R::splat(1.0));
    let cos_t = (R::splat(1.0) - sin2_t).sqrt();
    let fresnel = R::select(total, R::splat(1.0), fresnel_dielectric(cos_i, cos_t, eta_i, eta_t));
    let direction = (wo * -eta + n * (eta * cos_i - cos_t)).normalize();
    Refraction { fresnel, direction, eta, total }
}

/// Exact normalisation of the Blinn–Phong lobe at normal incidence
/// (Giesen 2009); the common (n + 8)/8π exceeds energy 1 for n > 4.
#[inline]
pub(crate) fn blinn_normalisation(exponent: f32) -> f32 {
    (exponent + 2.0) * (exponent + 4.0) / (8.0 * PI * ((-exponent * 0.5).exp2() + exponent))
}

/// A surface's scattering at one hit.
#[derive(Clone, Copy, Debug)]
pub enum Bsdf {
    Lambert {
        albedo: Rgb,
    },
    Phong {
        kd: Rgb,
        ks: Rgb,
        exponent: f32,
    },
    BlinnPhong {
        kd: Rgb,
        ks: Rgb,
        exponent: f32,
    },
    Mirror {
        tint: Rgb,
    },
    Glass {
        ior: f32,
        tint: Rgb,
    },
    /// Emitters reflect nothing.
    Black,
}

/// A glossy lobe's f and the pdf of its sampling, from one power: the
/// lobe's cosine `cos` (to the mirror direction for Phong, of the half
/// vector for Blinn–Phong) raised to `exponent`; the lobe is scaled by
/// `lobe_scale`, the lobe's pdf divided by `pdf_divisor`, and the diffuse
/// part taken with probability `pd`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn glossy_of<R: Real>(
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

/// Phong's f (the thesis' lobe, normalised: diffuse plus (n + 2)/2π · cosⁿ α
/// about the mirror direction) and the pdf of its sampling (the diffuse
/// lobe with probability `pd`, else cosⁿ α), for directions above the
/// surface.
#[inline(always)]
pub fn phong_of<R: Real>(kd: V3<R>, ks: V3<R>, exponent: R, pd: R, wo: V3<R>, wi: V3<R>, n: V3<R>) -> (V3<R>, R) {
    let cos_alpha = reflect_of(wo, n).dot(wi);
    let lobe_scale = (exponent + 2.0) * 0.5 * FRAC_1_PI;
    let lobe_scale = if faults::active(Fault::PhongLobeDim) { lobe_scale * 0.97 } else { lobe_scale };
    glossy_of(kd, ks, exponent, cos_alpha, lobe_scale, R::splat(1.0), pd, wi.dot(n))
}

/// Blinn–Phong's f (diffuse plus cosⁿ of the half vector, normalised by
/// `normalisation`, `blinn_normalisation` of the exponent) and the pdf of
/// its sampling (a half vector cosⁿ about the normal, turned into wi's
/// density), for directions above the surface.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn blinn_phong_of<R: Real>(
    kd: V3<R>,
    ks: V3<R>,
    exponent: R,
    normalisation: R,
    pd: R,
    wo: V3<R>,
    wi: V3<R>,
    n: V3<R>,
) -> (V3<R>, R) {
    let h = (wo + wi).normalize();
    glossy_of(kd, ks, exponent, n.dot(h), normalisation, wo.dot(h) * 4.0, pd, wi.dot(n))
}

impl Bsdf {
    #[inline]
    pub fn new(material: &MaterialModel) -> Self {
        match *material {
            MaterialModel::Lambert { albedo } => Bsdf::Lambert { albedo },
            MaterialModel::Phong { kd, ks, shininess, .. } => Bsdf::Phong { kd, ks, exponent: shininess },
            MaterialModel::BlinnPhong { kd, ks, shininess, .. } => Bsdf::BlinnPhong { kd, ks, exponent: shininess },
            MaterialModel::Mirror { tint } => Bsdf::Mirror { tint },
            MaterialModel::Glass { ior, tint } => Bsdf::Glass { ior, tint },
            MaterialModel::Emissive { .. } => Bsdf::Black,
        }
    }

    /// Only delta lobes: no light sampling, no photon storage.
    #[inline]
    pub fn is_specular(&self) -> bool {
        matches!(self, Bsdf::Mirror { .. } | Bsdf::Glass { .. } | Bsdf::Black)
    }

    /// The chance a path goes on after this surface under Russian roulette,
    /// as bidirectional methods play it: the surface's largest reflectance
    /// (at most 1), the same whichever way the path runs, so a subpath's
    /// density read backwards holds it too.
    #[inline]
    pub fn continuation(&self) -> f32 {
        let reflectance = match *self {
            Bsdf::Lambert { albedo } => albedo,
            Bsdf::Phong { kd, ks, .. } | Bsdf::BlinnPhong { kd, ks, .. } => kd + ks,
            Bsdf::Mirror { tint } | Bsdf::Glass { tint, .. } => tint,
            Bsdf::Black => Rgb::ZERO,
        };
        reflectance.max_element().min(1.0)
    }

    /// Probability of choosing the diffuse lobe of a Phong-like BRDF.
    #[inline]
    pub(crate) fn diffuse_probability(kd: Rgb, ks: Rgb) -> f32 {
        let (d, s) = (luminance(kd), luminance(ks));
        if d + s > 0.0 {
            d / (d + s)
        } else {
            1.0
        }
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
            Bsdf::Lambert { .. } => Some(self.eval(wo, n, n)),
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
    /// the glossy lobes out of line.
    #[inline(always)]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3, n: Vec3) -> (Rgb, f32) {
        if wi.dot(n) <= 0.0 || wo.dot(n) <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        match *self {
            Bsdf::Lambert { albedo } => (albedo * FRAC_1_PI, cosine_hemisphere_pdf_of(V3::dot(wi.into(), n.into()))),
            Bsdf::Phong { .. } | Bsdf::BlinnPhong { .. } => self.glossy_eval_pdf(wo, wi, n),
            Bsdf::Mirror { .. } | Bsdf::Glass { .. } | Bsdf::Black => (Rgb::ZERO, 0.0),
        }
    }

    /// `eval_pdf` of the glossy lobes, with both directions above the surface.
    #[inline(never)]
    fn glossy_eval_pdf(&self, wo: Vec3, wi: Vec3, n: Vec3) -> (Rgb, f32) {
        let (wo, wi, n) = (wo.into(), wi.into(), n.into());
        let (f, pdf) = match *self {
            Bsdf::Phong { kd, ks, exponent } => {
                phong_of(kd.into(), ks.into(), exponent, Self::diffuse_probability(kd, ks), wo, wi, n)
            }
            Bsdf::BlinnPhong { kd, ks, exponent } => {
                let (normalisation, pd) = (blinn_normalisation(exponent), Self::diffuse_probability(kd, ks));
                blinn_phong_of(kd.into(), ks.into(), exponent, normalisation, pd, wo, wi, n)
            }
            _ => return (Rgb::ZERO, 0.0),
        };
        (f.into(), pdf)
    }

    /// Draw an incoming direction. `n` is the geometric normal (any side);
    /// opaque models flip it to `wo`'s side, glass uses it to tell entering
    /// from leaving.
    #[inline]
    /// Each model draws from `sampler` only the numbers it uses.
    pub fn sample(&self, wo: Vec3, n: Vec3, sampler: &mut Sampler, transport: Transport) -> Option<BsdfSample> {
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let scattered = |wi: Vec3| -> Option<BsdfSample> {
            let (f, pdf) = self.eval_pdf(wo, wi, facing);
            if pdf <= 0.0 {
                return None;
            }
            let weight = f * (wi.dot(facing) / pdf);
            Some(BsdfSample { wi, weight, pdf, delta: false })
        };
        match *self {
            Bsdf::Lambert { albedo } => {
                let wi = Frame::from_z(facing).to_world(cosine_hemisphere(sampler.next_2d()));
                let cos = wi.dot(facing);
                (cos > 0.0).then(|| BsdfSample { wi, weight: albedo, pdf: cosine_hemisphere_pdf(cos), delta: false })
            }
            Bsdf::Phong { kd, ks, exponent } => {
                let (u_lobe, u) = (sampler.next_f32(), sampler.next_2d());
                let wi = if u_lobe < Self::diffuse_probability(kd, ks) {
                    Frame::from_z(facing).to_world(cosine_hemisphere(u))
                } else {
                    Frame::from_z(reflect(wo, facing)).to_world(power_cosine(u, exponent))
                };
                scattered(wi)
            }
            Bsdf::BlinnPhong { kd, ks, exponent } => {
                let (u_lobe, u) = (sampler.next_f32(), sampler.next_2d());
                let wi = if u_lobe < Self::diffuse_probability(kd, ks) {
                    Frame::from_z(facing).to_world(cosine_hemisphere(u))
                } else {
                    let h = Frame::from_z(facing).to_world(power_cosine(u, exponent));
                    reflect(wo, h)
                };
                scattered(wi)
            }
            Bsdf::Mirror { tint } => Some(BsdfSample { wi: reflect(wo, facing), weight: tint, pdf: 1.0, delta: true }),
            Bsdf::Glass { ior, tint } => {
                let entering = wo.dot(n) > 0.0;
                let (eta_i, eta_t) = if entering { (1.0, ior) } else { (ior, 1.0) };
                let (fresnel, refracted, eta) = refract(wo, facing, eta_i, eta_t);
                match refracted {
                    // A lobe to choose only where refraction is possible
                    Some(wt) if sampler.next_f32() >= fresnel => {
                        let scale = if transport == Transport::Radiance { eta * eta } else { 1.0 };
                        Some(BsdfSample { wi: wt, weight: tint * scale, pdf: 1.0 - fresnel, delta: true })
                    }
                    _ => Some(BsdfSample { wi: reflect(wo, facing), weight: tint, pdf: fresnel, delta: true }),
                }
            }
            Bsdf::Black => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::sampling::uniform_sphere;
    use std::f32::consts::FRAC_PI_2;

    fn directional_albedo(bsdf: &Bsdf, wo: Vec3, n: usize) -> Rgb {
        let mut s = Sampler::new(0, 0, 5);
        let mut sum = Rgb::ZERO;
        for _ in 0..n {
            if let Some(b) = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance) {
                sum += b.weight;
            }
        }
        sum / n as f32
    }

    #[test]
    fn sampled_weight_matches_eval_over_pdf() {
        let bsdfs = [
            Bsdf::Phong { kd: Vec3::splat(0.3), ks: Vec3::splat(0.6), exponent: 20.0 },
            Bsdf::BlinnPhong { kd: Vec3::splat(0.2), ks: Vec3::splat(0.7), exponent: 50.0 },
        ];
        let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
        let mut s = Sampler::new(1, 1, 1);
        for bsdf in bsdfs {
            let mut sampled = 0;
            for _ in 0..1000 {
                if let Some(b) = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance) {
                    sampled += 1;
                    let expected = bsdf.eval(wo, b.wi, Vec3::Z) * b.wi.z / bsdf.pdf(wo, b.wi, Vec3::Z);
                    assert!((expected - b.weight).abs().max_element() < 1e-3 * (1.0 + expected.max_element()));
                }
            }
            // Only directions below the surface fail, and the lobes lie mostly above it
            assert!(sampled > 800, "{bsdf:?}: {sampled} of 1000 samples");
        }
    }

    /// Where `front_constant` answers, it is `eval` for every direction in
    /// front, bit for bit, on either side of the surface; the lobes that
    /// depend on the direction do not answer.
    #[test]
    fn a_front_constant_is_eval_for_every_direction_in_front() {
        let mut s = Sampler::new(2, 2, 2);
        let lambert = Bsdf::Lambert { albedo: Vec3::new(0.7, 0.5, 0.2) };
        for _ in 0..2000 {
            let n = uniform_sphere(s.next_2d());
            let (wo, wi) = (uniform_sphere(s.next_2d()), uniform_sphere(s.next_2d()));
            let wi = if wi.dot(n) > 0.0 { wi } else { -wi };
            let constant = lambert.front_constant(wo, n).expect("Lambert's value is one");
            assert_eq!(constant, lambert.eval(wo, wi, n), "wo {wo}, wi {wi}, n {n}");
        }
        for bsdf in [
            Bsdf::Phong { kd: Vec3::splat(0.3), ks: Vec3::splat(0.6), exponent: 20.0 },
            Bsdf::BlinnPhong { kd: Vec3::splat(0.2), ks: Vec3::splat(0.7), exponent: 50.0 },
            Bsdf::Mirror { tint: Vec3::ONE },
            Bsdf::Glass { ior: 1.5, tint: Vec3::ONE },
        ] {
            assert_eq!(bsdf.front_constant(Vec3::Z, Vec3::Z), None, "{bsdf:?}");
        }
    }

    #[test]
    fn lambert_albedo_is_exact() {
        let a = directional_albedo(&Bsdf::Lambert { albedo: Vec3::splat(0.5) }, Vec3::Z, 1000);
        assert!((a - Vec3::splat(0.5)).abs().max_element() < 1e-6);
    }

    #[test]
    fn glass_fresnel_at_normal_incidence_and_total_internal_reflection() {
        let (f, t, _) = refract(Vec3::Z, Vec3::Z, 1.0, 1.5);
        assert!((f - 0.04).abs() < 1e-6);
        assert!((t.unwrap() + Vec3::Z).length() < 1e-6);
        // Leaving glass at 60° (critical angle ≈ 41.8°): everything reflects
        let wo = Vec3::new(60f32.to_radians().sin(), 0.0, 60f32.to_radians().cos());
        let (f, t, _) = refract(wo, Vec3::Z, 1.5, 1.0);
        assert_eq!(f, 1.0);
        assert!(t.is_none());
    }

    /// A random unit vector and one in the hemisphere around it.
    fn unit_and_front(s: &mut Sampler) -> (Vec3, Vec3) {
        let n = uniform_sphere(s.next_2d());
        let w = uniform_sphere(s.next_2d());
        (n, if w.dot(n) < 0.0 { -w } else { w })
    }

    #[test]
    fn reflection_mirrors_about_the_normal() {
        let r = reflect(Vec3::new(1.0, 2.0, 0.0).normalize(), Vec3::Y);
        assert!((r - Vec3::new(-1.0, 2.0, 0.0).normalize()).length() < 1e-6, "{r}");
        let mut s = Sampler::new(3, 3, 3);
        for _ in 0..1000 {
            let (n, w) = unit_and_front(&mut s);
            let r = reflect(w, n);
            // Same angle to the normal, same length, and w + r along the normal
            assert!((r.dot(n) - w.dot(n)).abs() < 1e-5 && (r.length() - 1.0).abs() < 1e-5, "{w} about {n}: {r}");
            assert!((w + r).cross(n).length() < 1e-5, "{w} about {n}: {r}");
        }
    }

    /// Fresnel's equations in the angles (Born and Wolf), in f64: the
    /// reflectance `refract` gives, entering glass and leaving it below the
    /// critical angle; the parallel part vanishes at Brewster's angle.
    #[test]
    fn fresnel_is_the_angle_form() {
        let oracle = |theta_i: f64, eta_i: f64, eta_t: f64| {
            let theta_t = (eta_i / eta_t * theta_i.sin()).asin();
            let (d, s) = (theta_i - theta_t, theta_i + theta_t);
            ((d.sin() / s.sin()).powi(2) + (d.tan() / s.tan()).powi(2)) / 2.0
        };
        for (eta_i, eta_t) in [(1.0f32, 1.5f32), (1.5, 1.0), (1.0, 2.4)] {
            let critical = if eta_i > eta_t { (eta_t / eta_i).asin() } else { FRAC_PI_2 };
            for k in 1..40 {
                let theta = critical * k as f32 / 40.0;
                let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                let (fresnel, _, _) = refract(wo, Vec3::Z, eta_i, eta_t);
                let expected = oracle(theta as f64, eta_i as f64, eta_t as f64);
                assert!(
                    (fresnel as f64 - expected).abs() < 1e-5,
                    "{eta_i}→{eta_t} at {theta}: {fresnel} vs {expected}"
                );
            }
            // At Brewster's angle only the perpendicular part is left
            let brewster = (eta_t / eta_i).atan();
            let wo = Vec3::new(brewster.sin(), 0.0, brewster.cos());
            let (fresnel, _, _) = refract(wo, Vec3::Z, eta_i, eta_t);
            let theta_t = (eta_i / eta_t * brewster.sin()).asin();
            let perpendicular = ((brewster - theta_t).sin() / (brewster + theta_t).sin()).powi(2);
            assert!((fresnel - perpendicular / 2.0).abs() < 1e-5, "{eta_i}→{eta_t} at Brewster: {fresnel}");
        }
    }

    /// Snell: η_i sin θ_i = η_t sin θ_t, in the plane of incidence, through
    /// to the other side; total internal reflection just past the critical
    /// angle and not just before it.
    #[test]
    fn refraction_obeys_snell() {
        let mut s = Sampler::new(4, 4, 4);
        for (eta_i, eta_t) in [(1.0f32, 1.5f32), (1.5, 1.0), (1.33, 1.0)] {
            let mut refracted = 0;
            for _ in 0..2000 {
                let (n, wo) = unit_and_front(&mut s);
                let (_, t, eta) = refract(wo, n, eta_i, eta_t);
                assert_eq!(eta, eta_i / eta_t);
                let sin_i = wo.cross(n).length();
                let Some(t) = t else {
                    assert!(eta_i * sin_i > eta_t * (1.0 - 1e-4), "reflected at sin θ {sin_i}, {eta_i}→{eta_t}");
                    continue;
                };
                refracted += 1;
                assert!((t.length() - 1.0).abs() < 1e-5 && t.dot(n) < 0.0, "{t}");
                assert!((eta_i * sin_i - eta_t * t.cross(n).length()).abs() < 1e-4, "{wo} → {t} about {n}");
                assert!(wo.cross(n).dot(t).abs() < 1e-5, "{t} leaves the plane of {wo} and {n}");
            }
            assert!(refracted > 500, "{refracted} refracted, {eta_i}→{eta_t}");
            if eta_i > eta_t {
                let critical = (eta_t / eta_i).asin();
                let at = |theta: f32| refract(Vec3::new(theta.sin(), 0.0, theta.cos()), Vec3::Z, eta_i, eta_t).1;
                assert!(at(critical * 0.999).is_some() && at(critical * 1.001).is_none());
            }
        }
    }

    /// The diffuse lobe is chosen by its share of the luminance (Rec. 709).
    #[test]
    fn the_diffuse_lobe_is_chosen_by_its_luminance_share() {
        let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
        let share = Bsdf::diffuse_probability(red, green);
        assert!((share - 0.2126 / (0.2126 + 0.7152)).abs() < 1e-6, "{share}");
        let share = Bsdf::diffuse_probability(blue * 2.0, red);
        assert!((share - 0.1444 / (0.1444 + 0.2126)).abs() < 1e-6, "{share}");
        assert_eq!(Bsdf::diffuse_probability(blue, Vec3::ZERO), 1.0);
        assert_eq!(Bsdf::diffuse_probability(Vec3::ZERO, green), 0.0);
        assert_eq!(Bsdf::diffuse_probability(Vec3::ZERO, Vec3::ZERO), 1.0);
    }

    /// Giesen's normalisation makes the Blinn–Phong lobe reflect all it
    /// receives at normal incidence: 2π ∫ N cosⁿ(θ/2) cos θ sin θ dθ = 1
    /// (the half vector lies halfway to the normal), by Simpson's rule in f64.
    #[test]
    fn blinn_phong_reflects_everything_at_normal_incidence() {
        for exponent in [0.5f32, 1.0, 4.0, 10.0, 100.0, 1000.0] {
            let normalisation = blinn_normalisation(exponent) as f64;
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

    /// ∫ g(wi) dωi over the hemisphere about +z, by the midpoint rule in
    /// (cos θ, φ) (where dω = d cos θ dφ), in f64.
    fn over_the_hemisphere(g: impl Fn(Vec3) -> f64) -> f64 {
        let (rings, sectors) = (1200, 64);
        let mut sum = 0.0;
        for i in 0..rings {
            let cos = (i as f64 + 0.5) / rings as f64;
            let sin = (1.0 - cos * cos).sqrt();
            for j in 0..sectors {
                let phi = (j as f64 + 0.5) / sectors as f64 * std::f64::consts::TAU;
                sum += g(Vec3::new((sin * phi.cos()) as f32, (sin * phi.sin()) as f32, cos as f32));
            }
        }
        sum * std::f64::consts::TAU / (rings * sectors) as f64
    }

    /// At normal incidence every glossy lobe lies above the surface: the
    /// normalised lobes reflect all they receive (ks = 1), the diffuse part
    /// its kd, and the sampling pdf integrates to 1 for Phong, whose lobe is
    /// about the normal, and for Blinn–Phong to the diffuse share plus the
    /// half vectors within 45° of the normal, 1 − cos^(n+1)(π/4).
    #[test]
    fn glossy_lobes_at_normal_incidence() {
        let n = Vec3::Z;
        let luminance_share = |kd: f32, ks: f32| kd / (kd + ks);
        for exponent in [1.0f32, 10.0, 40.0] {
            for (kd, ks) in [(0.0f32, 1.0f32), (0.5, 0.0), (0.3, 0.6)] {
                let phong = Bsdf::Phong { kd: Vec3::splat(kd), ks: Vec3::splat(ks), exponent };
                let blinn = Bsdf::BlinnPhong { kd: Vec3::splat(kd), ks: Vec3::splat(ks), exponent };
                let pd = luminance_share(kd, ks) as f64;
                let blinn_reach = 1.0 - std::f64::consts::FRAC_1_SQRT_2.powf(exponent as f64 + 1.0);
                for (bsdf, pdf_total) in [(phong, 1.0), (blinn, pd + (1.0 - pd) * blinn_reach)] {
                    let albedo = over_the_hemisphere(|wi| (bsdf.eval(n, wi, n).x * wi.z) as f64);
                    let pdf = over_the_hemisphere(|wi| bsdf.pdf(n, wi, n) as f64);
                    let what = format!("{bsdf:?}");
                    // The quadrature's own error here is below 5e-5
                    assert!((albedo - (kd + ks) as f64).abs() < 5e-4, "{what}: albedo {albedo}");
                    assert!((pdf - pdf_total).abs() < 5e-4, "{what}: pdf integrates to {pdf}, not {pdf_total}");
                }
            }
        }
    }

    /// A glass sample says how likely its own choice was: F for the
    /// reflection, 1 − F for the refraction (what a bidirectional method's
    /// reverse density reads), and chooses them that often.
    #[test]
    fn glass_samples_carry_the_chance_of_their_lobe() {
        let glass = Bsdf::Glass { ior: 1.5, tint: Vec3::ONE };
        let mut s = Sampler::new(5, 5, 5);
        for (wo, n) in [(Vec3::new(0.6, 0.0, 0.8), Vec3::Z), (Vec3::new(0.3, 0.0, -0.953_939_2), Vec3::Z)] {
            let facing = if wo.dot(n) < 0.0 { -n } else { n };
            let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
            let (fresnel, refracted, _) = refract(wo, facing, eta_i, eta_t);
            let refracted = refracted.expect("below the critical angle");
            let trials = 20_000;
            let mut reflections = 0;
            for _ in 0..trials {
                let b = glass.sample(wo, n, &mut s, Transport::Importance).expect("glass always scatters");
                assert!(b.delta);
                if b.wi == reflect(wo, facing) {
                    reflections += 1;
                    assert_eq!(b.pdf, fresnel);
                } else {
                    assert_eq!((b.wi, b.pdf), (refracted, 1.0 - fresnel));
                }
            }
            // Binomial: 5 standard deviations
            let sigma = (trials as f32 * fresnel * (1.0 - fresnel)).sqrt();
            assert!(
                (reflections as f32 - trials as f32 * fresnel).abs() < 5.0 * sigma,
                "{reflections} of {trials}, F = {fresnel}"
            );
        }
    }

    /// Russian roulette's chance to go on: the largest reflectance, at most 1.
    #[test]
    fn continuation_is_the_largest_reflectance() {
        let c = |bsdf: Bsdf| bsdf.continuation();
        assert_eq!(c(Bsdf::Lambert { albedo: Vec3::new(0.2, 0.7, 0.4) }), 0.7);
        let (kd, ks) = (Vec3::new(0.25, 0.5, 0.125), Vec3::new(0.5, 0.125, 0.125));
        assert_eq!(c(Bsdf::Phong { kd, ks, exponent: 8.0 }), 0.75);
        assert_eq!(c(Bsdf::BlinnPhong { kd: Vec3::splat(0.8), ks: Vec3::splat(0.5), exponent: 8.0 }), 1.0);
        assert_eq!(c(Bsdf::Glass { ior: 1.5, tint: Vec3::new(0.9, 0.3, 0.3) }), 0.9);
        assert_eq!(c(Bsdf::Black), 0.0);
    }

    /// Reflection only: nothing for a direction behind the surface, on
    /// either side.
    #[test]
    fn nothing_is_reflected_from_behind() {
        let phong = Bsdf::Phong { kd: Vec3::splat(0.3), ks: Vec3::splat(0.6), exponent: 2.0 };
        let (front, behind) = (Vec3::new(0.3, 0.0, 0.95).normalize(), Vec3::new(0.3, 0.0, -0.95).normalize());
        assert!(phong.eval_pdf(front, front, Vec3::Z).1 > 0.0);
        assert_eq!(phong.eval_pdf(front, behind, Vec3::Z), (Rgb::ZERO, 0.0));
        assert_eq!(phong.eval_pdf(behind, front, Vec3::Z), (Rgb::ZERO, 0.0));
    }
}
