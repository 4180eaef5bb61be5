//! The optics every material shares: mirror reflection, and refraction
//! with Fresnel's reflectance at a dielectric interface.

use glam::Vec3;

use crate::geometry::real::{Real, V3};

#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    reflect_of(w.into(), n.into()).into()
}

/// `reflect` for one direction or several.
#[inline(always)]
pub fn reflect_of<R: Real>(w: V3<R>, n: V3<R>) -> V3<R> {
    n * (w.dot(n) * 2.0) - w
}

/// Unpolarised Fresnel reflectance of a dielectric interface.
#[inline(always)]
pub fn fresnel_dielectric<R: Real>(cos_i: R, cos_t: R, eta_i: R, eta_t: R) -> R {
    let parallel = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    let perpendicular = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    (parallel * parallel + perpendicular * perpendicular) * 0.5
}

/// Unpolarised Fresnel reflectance of a conductor of complex index
/// η + ik (relative to the medium outside) at the cosine `cos_i`, per
/// channel: the exact form for both polarisations (as Mitsuba 0.6 wrote it).
#[inline(always)]
pub fn fresnel_conductor_of<R: Real>(cos_i: R, eta: V3<R>, k: V3<R>) -> V3<R> {
    V3::new(
        fresnel_conductor_channel(cos_i, eta.x, k.x),
        fresnel_conductor_channel(cos_i, eta.y, k.y),
        fresnel_conductor_channel(cos_i, eta.z, k.z),
    )
}

/// One channel of `fresnel_conductor_of` (a function, not a closure: a
/// closure is not always inlined, and out of line the lanes' intrinsics
/// would be calls).
#[inline(always)]
fn fresnel_conductor_channel<R: Real>(cos_i: R, eta: R, k: R) -> R {
    let cos2 = cos_i * cos_i;
    let sin2 = R::splat(1.0) - cos2;
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2_plus_b2 = (t0 * t0 + eta2 * k2 * 4.0).sqrt();
    let a = ((a2_plus_b2 + t0) * 0.5).max(R::splat(0.0)).sqrt();
    let (t1, t2) = (a2_plus_b2 + cos2, a * cos_i * 2.0);
    let perpendicular = (t1 - t2) / (t1 + t2);
    let (t3, t4) = (a2_plus_b2 * cos2 + sin2 * sin2, t2 * sin2);
    let parallel = perpendicular * (t3 - t4) / (t3 + t4);
    (parallel + perpendicular) * 0.5
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;
    use std::f32::consts::FRAC_PI_2;

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

    /// A conductor's reflectance is Fresnel's equations with a complex
    /// index n = η + ik, r_s = (cos θi − n cos θt)/(cos θi + n cos θt),
    /// r_p = (n cos θi − cos θt)/(n cos θi + cos θt), cos θt = √(1 − sin²θi/n²),
    /// in complex f64 arithmetic; with k = 0 it is the dielectric's.
    #[test]
    fn conductor_fresnel_is_the_complex_form() {
        type C = (f64, f64);
        let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let div = |a: C, b: C| {
            let d = b.0 * b.0 + b.1 * b.1;
            ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
        };
        let sqrt = |a: C| {
            let r = (a.0 * a.0 + a.1 * a.1).sqrt();
            (((r + a.0) / 2.0).sqrt(), ((r - a.0) / 2.0).sqrt().copysign(a.1))
        };
        let norm2 = |a: C| a.0 * a.0 + a.1 * a.1;
        let oracle = |cos_i: f64, n: C| {
            let sin2 = 1.0 - cos_i * cos_i;
            let s = div((sin2, 0.0), mul(n, n));
            let cos_t = sqrt((1.0 - s.0, -s.1));
            let n_cos_t = mul(n, cos_t);
            let n_cos_i = (n.0 * cos_i, n.1 * cos_i);
            let r_s = div((cos_i - n_cos_t.0, -n_cos_t.1), (cos_i + n_cos_t.0, n_cos_t.1));
            let r_p = div((n_cos_i.0 - cos_t.0, n_cos_i.1 - cos_t.1), (n_cos_i.0 + cos_t.0, n_cos_i.1 + cos_t.1));
            (norm2(r_s) + norm2(r_p)) / 2.0
        };
        let gold = (Vec3::new(0.143, 0.375, 1.442), Vec3::new(3.983, 2.386, 1.603));
        let aluminium = (Vec3::new(1.658, 0.880, 0.521), Vec3::new(9.224, 6.270, 4.837));
        let glass = (Vec3::splat(1.5), Vec3::ZERO);
        for (eta, k) in [gold, aluminium, glass] {
            for step in 0..=40 {
                let cos_i = step as f32 / 40.0;
                let fresnel: Vec3 = fresnel_conductor_of(cos_i, eta.into(), k.into()).into();
                for c in 0..3 {
                    let expected = oracle(cos_i as f64, (eta[c] as f64, k[c] as f64));
                    assert!(
                        (fresnel[c] as f64 - expected).abs() < 2e-5,
                        "η {eta}, k {k} at cos {cos_i}: {} vs {expected}",
                        fresnel[c]
                    );
                }
            }
            let dielectric = fresnel_dielectric(1.0f32, 1.0, 1.0, eta.x);
            if k == Vec3::ZERO {
                assert!((fresnel_conductor_of(1.0f32, eta.into(), k.into()).x - dielectric).abs() < 1e-6);
            }
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
}
