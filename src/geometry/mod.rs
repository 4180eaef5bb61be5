//! Rays, shapes and their intersection, written to stay right in f32 on hard
//! cases: huge spheres used as walls, rays from far away, grazing and tangent
//! rays, rays spawned on surfaces. Nothing here knows about materials or light.

mod cull;
mod frame;
mod plane;
pub mod pow;
mod ray;
pub mod real;
pub mod sphere;
mod triangle;

pub use cull::{beyond, Crossing, CullEdges, CullPlane, TriangleCull};
pub use frame::{frame_from_z, to_local, to_world, Frame};
pub use plane::intersect_plane;
pub(crate) use plane::{plane_exit_of, plane_exit_t, plane_hit, plane_point_of, plane_t, plane_t_of};
pub use ray::{gamma, offset_origin, offset_ray_origin, spawn_offset_scale, Ray};
pub use sphere::intersect_sphere;
pub(crate) use sphere::sphere_hit;
pub use sphere::sphere_t;
#[cfg(test)]
pub(crate) use triangle::shear_of;
pub(crate) use triangle::{edges_of, ray_shear_of, triangle_hit_of, RayShear};
pub use triangle::{intersect_triangle, Triangle};
pub(crate) use triangle::{watertight_finish_of, watertight_range_of};

use glam::Vec3;
use real::{Real, V3};

/// A surface point found by a ray: where, how far, which way the surface faces,
/// and how far the computed point may be from the true surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The hit point in world space (re-projected onto the surface where possible).
    pub point: Vec3,
    /// Unit geometric normal, outward for spheres, as given for planes and by the
    /// winding (b − a) × (c − a) for triangles.
    pub normal: Vec3,
    /// Bound on the absolute error of `point` along any axis; ray origins spawned
    /// here are pushed out by at least this much.
    pub error: f32,
}

impl SurfaceHit {
    /// A ray leaving this hit in `direction`, with its origin offset to the side
    /// of the surface the direction points to, so it cannot re-hit the surface.
    #[inline]
    pub fn spawn_ray(&self, direction: Vec3) -> Ray {
        Ray::new(offset_ray_origin(self.point, self.error, self.normal, direction), direction)
    }

    /// A ray from this hit toward `target`, with `t_max` just short of it, for
    /// shadow tests; the target's own error bound keeps it off the far surface.
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3, target_error: f32) -> (Ray, f32) {
        let (origin, direction, t_max) =
            ray_to(self.point.into(), self.error, self.normal.into(), target.into(), target_error);
        (Ray::new(origin.into(), direction.into()), t_max)
    }
}

/// `SurfaceHit::spawn_ray_to` for one point or several: (origin, unit
/// direction, t_max).
#[inline(always)]
pub fn ray_to<R: Real>(point: V3<R>, error: R, normal: V3<R>, target: V3<R>, target_error: R) -> (V3<R>, V3<R>, R) {
    let origin = ray::offset_origin(point, error, normal, target - point);
    let to_target = target - origin;
    let distance = to_target.length();
    let margin = target_error.max(ray::spawn_offset_scale(target)) * 4.0;
    (origin, to_target / distance, (distance - margin).max(R::splat(0.0)))
}
