use glam::Vec3;

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
    let denominator = normal.dot(ray.direction);
    if denominator == 0.0 {
        return None;
    }
    let t = (offset - normal.dot(ray.origin)) / denominator;
    (t > 0.0 && t < t_max).then_some(t)
}

/// Where a ray leaves the half-space `inward · x > offset` that holds its
/// path (an opaque wall's side it started on), in [0, t_max): never while
/// heading in, and at once (0) where rounding has already put the origin
/// on the far side heading out; see `sphere::wall_exit`.
#[inline]
pub(crate) fn plane_exit_t(ray: &Ray, inward: Vec3, offset: f32, t_max: f32) -> Option<f32> {
    let denominator = inward.dot(ray.direction);
    if denominator >= 0.0 {
        return None;
    }
    let t = ((offset - inward.dot(ray.origin)) / denominator).max(0.0);
    (t < t_max).then_some(t)
}

#[inline]
pub(crate) fn plane_hit(ray: &Ray, normal: Vec3, offset: f32, t: f32) -> SurfaceHit {
    // Re-project onto the plane so the error does not grow with t
    let along = ray.at(t);
    let point = along - normal * (normal.dot(along) - offset);
    SurfaceHit { t, point, normal, error: gamma(7) * (point.abs().element_sum() + offset.abs()) }
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
