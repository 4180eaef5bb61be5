//! The scene's shapes, one file per kind: what each is compiled into for
//! the hit loops and the occluders, and, for those that can emit, how a
//! light is sampled on it (`AreaEmitter`).
//! - `sphere`: spheres four to a SIMD group, and a sphere light's cap;
//! - `plane`: infinite planes (found by rays, never sampled);
//! - `triangle`: triangles four to a SIMD group behind a test of where the
//!   ray crosses their plane.

pub mod plane;
pub mod sphere;
pub mod triangle;

use glam::{DVec3, Vec2, Vec3};

use crate::geometry::real::{Real, V3};
use crate::geometry::SurfaceHit;
pub use plane::PlaneShape;
pub use sphere::{CappedSphere, EmitterCap, SphereLanes, Spheres};
pub use triangle::TriangleLanes;

/// What a shape that can be an area light answers, written once per kind;
/// `light::Emitter` dispatches to it.
pub trait AreaEmitter {
    /// The emitting area.
    fn area(&self) -> f32;

    /// Whether `point` (on the shape) lies where it emits.
    fn emits_at(&self, point: Vec3) -> bool;

    /// Bound on the error of points computed on it.
    fn error(&self) -> f32;

    /// A point uniform over its emitting area: (point, outward normal).
    fn uniform_point(&self, u: Vec2) -> (Vec3, Vec3);

    /// A point as seen from `p`: (point, outward normal, solid-angle pdf
    /// at `p`), `None` where nothing can be drawn.
    fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32)>;

    /// The solid-angle pdf with which `sample_from` draws `hit` from `p`.
    fn pdf_from(&self, p: Vec3, hit: &SurfaceHit) -> f32;

    /// Whether every point it emits from lies in a region, given as
    /// `holds(centre, reach)`: whether the ball there lies in it.
    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool) -> bool;
}

/// A uniform-area pdf 1/area turned into solid angle at `p`: d²/(cos θ·A),
/// 0 when the light's front faces away.
#[inline]
pub fn solid_angle_pdf(p: Vec3, point: Vec3, normal: Vec3, area: f32) -> f32 {
    solid_angle_pdf_of(p.into(), point.into(), normal.into(), area)
}

/// `solid_angle_pdf` for one point or several.
#[inline(always)]
pub fn solid_angle_pdf_of<R: Real>(p: V3<R>, point: V3<R>, normal: V3<R>, area: R) -> R {
    let to_light = point - p;
    let distance2 = to_light.length_squared();
    let cos_light = normal.dot(-to_light) / distance2.sqrt();
    R::select(cos_light.gt(R::splat(0.0)), distance2 / (cos_light * area), R::splat(0.0))
}

/// Which flat array an object's shape lives in, and where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeRef {
    Sphere(u32),
    Plane(u32),
    Triangle(u32),
}

#[derive(Clone, Copy, Debug)]
pub struct ObjectInfo {
    pub shape: ShapeRef,
    pub material: u32,
    /// Index into `World::lights` when the object is a sampled area light.
    pub light: Option<u32>,
}
