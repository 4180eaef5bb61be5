use glam::Vec3;

use super::real::{Mask, Real, V3};
use super::{gamma, Ray, SurfaceHit};

/// Nearest hit of `ray` with the sphere in (0, t_max).
///
/// The textbook `−b ± √(b² − c)` cancels catastrophically for large spheres
/// and distant rays; this is the stable form of Haines et al., Ray Tracing
/// Gems ch. 7: the discriminant from the ray's closest approach to the centre,
/// and the smaller root as `c / q`.
#[inline]
pub fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32, t_max: f32) -> Option<SurfaceHit> {
    let (t, near) = sphere_t(ray, center, radius, t_max)?;
    Some(sphere_hit(ray, center, radius, t, near))
}

/// The nearest root in (0, t_max) and whether it is the near one (entering),
/// without building the hit record (the nearest-hit loop only needs `t`).
/// Which root matters: from far away both round to the same `t`.
#[inline]
pub fn sphere_t(ray: &Ray, center: Vec3, radius: f32, t_max: f32) -> Option<(f32, bool)> {
    let f = V3::from(ray.origin - center);
    let (t, hit, near) = nearest_root(f, ray.direction.into(), radius * radius, t_max);
    hit.then_some((t, near))
}

/// The roots of a sphere of squared radius `radius2` along rays of unit
/// `direction`, from `f` = origin − centre: (near, far, discriminant). The
/// discriminant comes from the closest approach, the root that adds
/// magnitudes first and the other from Vieta (t0·t1 = c).
#[inline(always)]
pub fn roots<R: Real>(f: V3<R>, direction: V3<R>, radius2: R) -> (R, R, R) {
    let b = f.dot(direction);
    let closest = f - direction * b;
    let discriminant = radius2 - closest.length_squared();
    let c = f.length_squared() - radius2;
    let q = -b - discriminant.max(R::splat(0.0)).sqrt().copysign(b);
    let t0 = c / q;
    (t0.min(q), t0.max(q), discriminant)
}

/// The nearest root in (0, t_max): (t, whether there is one, whether it is
/// the near root). A ray starting inside takes the far root; q == 0 (a ray
/// through the centre starting on it) gives NaN, which no comparison passes.
#[inline(always)]
pub fn nearest_root<R: Real>(f: V3<R>, direction: V3<R>, radius2: R, t_max: R) -> (R, R::Mask, R::Mask) {
    let (near, far, discriminant) = roots(f, direction, radius2);
    let zero = R::splat(0.0);
    let near_ok = near.gt(zero).and(near.lt(t_max));
    let t = R::select(near_ok, near, far);
    let hit = discriminant.ge(zero).and(t.gt(zero)).and(t.lt(t_max));
    (t, hit, near_ok)
}

#[inline]
pub(crate) fn sphere_hit(ray: &Ray, center: Vec3, radius: f32, t: f32, near: bool) -> SurfaceHit {
    // Rebuild the point from the closest approach rather than origin + t·d:
    // from far away t is only good to ulp(t), the closest-approach vector to
    // ulp(radius).
    let f = ray.origin - center;
    let closest = f - f.dot(ray.direction) * ray.direction;
    let half_chord = (radius * radius - closest.length_squared()).max(0.0).sqrt();
    let from_center = if near { closest - half_chord * ray.direction } else { closest + half_chord * ray.direction };
    let length = from_center.length();
    let normal = if length > 0.0 { from_center / length } else { -ray.direction };
    SurfaceHit { t, point: center + normal * radius, normal, error: gamma(6) * (center.abs().max_element() + radius) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Nearest positive root in f64, the oracle for the f32 code.
    fn oracle(origin: DVec3, direction: DVec3, center: DVec3, radius: f64) -> Option<f64> {
        let d = direction.normalize();
        let f = origin - center;
        let b = f.dot(d);
        let disc = radius * radius - (f - b * d).length_squared();
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        [-b - s, -b + s].into_iter().find(|t| *t > 0.0)
    }

    #[test]
    fn tiny_sphere_from_ten_million_units() {
        let ray = Ray::new(Vec3::new(-1.0e7, 0.095, 0.0), Vec3::X);
        let hit = intersect_sphere(&ray, Vec3::ZERO, 0.1, f32::INFINITY).expect("must hit");
        let t = oracle(DVec3::new(-1.0e7, 0.095, 0.0), DVec3::X, DVec3::ZERO, 0.1).unwrap();
        // f32 cannot place the origin better than ulp(1e7) = 1, so t is good to ~1
        assert!((hit.t as f64 - t).abs() <= 1.0, "{} vs {t}", hit.t);
        assert!((hit.point.length() - 0.1).abs() < 1e-6);
        assert!(hit.normal.x < 0.0);
    }

    #[test]
    fn smallpt_walls_from_the_camera() {
        // Left wall of smallpt seen from inside the box
        let center = Vec3::new(1.0e5 + 1.0, 40.8, 81.6);
        let origin = Vec3::new(50.0, 52.0, 155.6);
        // The room is inside every wall's sphere: the wall at x = 1 is its near side
        for dir in [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(-1.0, -0.3, -0.2), Vec3::new(-0.6, 0.1, -1.0)] {
            let d = dir.normalize();
            let hit = intersect_sphere(&Ray::new(origin, d), center, 1.0e5, f32::INFINITY).unwrap();
            let t = oracle(origin.as_dvec3(), d.as_dvec3(), center.as_dvec3(), 1.0e5).unwrap();
            assert!((hit.t as f64 - t).abs() < 1e-3 * t.max(1.0), "{} vs {t}", hit.t);
            assert!(hit.point.x > 0.9 && hit.point.x < 1.1);
            assert!(hit.error >= 1e-3, "error bound must cover the centre's rounding");
        }
    }

    #[test]
    fn tangent_and_grazing_rays_stay_finite() {
        for y in [0.999_999f32, 1.0, 1.000_001, 0.9999] {
            let ray = Ray::new(Vec3::new(-5.0, y, 0.0), Vec3::X);
            if let Some(hit) = intersect_sphere(&ray, Vec3::ZERO, 1.0, f32::INFINITY) {
                assert!(hit.t.is_finite() && hit.point.is_finite() && hit.normal.is_finite());
                assert!((hit.point.length() - 1.0).abs() < 1e-5);
            }
        }
        assert!(
            intersect_sphere(&Ray::new(Vec3::new(-5.0, 1.001, 0.0), Vec3::X), Vec3::ZERO, 1.0, f32::INFINITY).is_none()
        );
    }

    #[test]
    fn from_inside_finds_the_far_side() {
        let ray = Ray::new(Vec3::ZERO, Vec3::Y);
        let hit = intersect_sphere(&ray, Vec3::ZERO, 2.0, f32::INFINITY).unwrap();
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert!(intersect_sphere(&ray, Vec3::ZERO, 2.0, 1.5).is_none());
    }
}
