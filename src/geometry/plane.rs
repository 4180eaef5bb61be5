use glam::Vec3;

use super::real::{Mask, Real, V3};
use super::{gamma, Ray, SurfaceHit};

/// Hit of `ray` with the infinite plane `normal · x = offset` in (0, t_max).
/// A ray parallel to the plane (including one lying in it) misses.
#[inline]
pub fn intersect_plane(ray: &Ray, normal: Vec3, offset: f32, t_max: f32) -> Option<SurfaceHit> {
    let t = plane_t(ray, normal, offset, t_max)?;
    Some(plane_hit(ray, normal, offset, t))
}

#[inline]
pub(crate) fn plane_t(ray: &Ray, normal: Vec3, offset: f32, t_max: f32) -> Option<f32> {
    let (t, hits) = plane_t_of(V3::from(ray.origin), V3::from(ray.direction), V3::from(normal), offset, t_max);
    hits.then_some(t)
}

/// `plane_t` in any lanes: t, and where it lies in (0, t_max) (nowhere
/// for a ray parallel to the plane).
#[inline(always)]
pub(crate) fn plane_t_of<R: Real>(origin: V3<R>, direction: V3<R>, normal: V3<R>, offset: R, t_max: R) -> (R, R::Mask) {
    let zero = R::splat(0.0);
    let denominator = normal.dot(direction);
    let t = (offset - normal.dot(origin)) / denominator;
    (t, denominator.ne(zero).and(t.gt(zero)).and(t.lt(t_max)))
}

/// Where a ray leaves the half-space `inward · x > offset` that holds its
/// path (an opaque wall's side it started on), in [0, t_max): never while
/// heading in, and at once (0) where rounding has already put the origin
/// on the far side heading out; see `sphere::wall_exit`.
#[inline]
pub(crate) fn plane_exit_t(ray: &Ray, inward: Vec3, offset: f32, t_max: f32) -> Option<f32> {
    let (t, exits) = plane_exit_of(V3::from(ray.origin), V3::from(ray.direction), V3::from(inward), offset, t_max);
    exits.then_some(t)
}

/// `plane_exit_t` in any lanes: t, and where the ray leaves before t_max.
#[inline(always)]
pub(crate) fn plane_exit_of<R: Real>(
    origin: V3<R>,
    direction: V3<R>,
    inward: V3<R>,
    offset: R,
    t_max: R,
) -> (R, R::Mask) {
    let zero = R::splat(0.0);
    let denominator = inward.dot(direction);
    let t = ((offset - inward.dot(origin)) / denominator).max(zero);
    (t, t.lt(t_max).and_not(denominator.ge(zero)))
}

#[inline]
pub(crate) fn plane_hit(ray: &Ray, normal: Vec3, offset: f32, t: f32) -> SurfaceHit {
    let (point, error) = plane_point_of(V3::from(ray.origin), V3::from(ray.direction), V3::from(normal), offset, t);
    SurfaceHit { t, point: point.into(), normal, error }
}

/// The point of `plane_hit` in any lanes, and the bound on its error.
#[inline(always)]
pub(crate) fn plane_point_of<R: Real>(origin: V3<R>, direction: V3<R>, normal: V3<R>, offset: R, t: R) -> (V3<R>, R) {
    // Re-project onto the plane so the error does not grow with t
    let along = origin + direction * t;
    let point = along - normal * (normal.dot(along) - offset);
    (point, R::splat(gamma(7)) * (point.abs().element_sum() + offset.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_and_in_plane_rays_miss() {
        let n = Vec3::Y;
        assert!(intersect_plane(&Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::X), n, 0.0, f32::INFINITY).is_none());
        assert!(intersect_plane(&Ray::new(Vec3::ZERO, Vec3::X), n, 0.0, f32::INFINITY).is_none());
        // -0.0 components are parallel too
        assert!(intersect_plane(&Ray::new(Vec3::Y, Vec3::new(1.0, -0.0, 0.0)), n, 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn long_ray_lands_on_the_plane() {
        let d = Vec3::new(1.0, -1.0e-6, 0.0).normalize();
        let hit = intersect_plane(&Ray::new(Vec3::new(0.0, 1.0, 0.0), d), Vec3::Y, 0.0, f32::INFINITY).unwrap();
        assert!(hit.t > 9.0e5 && hit.t.is_finite());
        assert!(hit.point.y.abs() <= hit.error);
    }
}
