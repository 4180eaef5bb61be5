//! The scene's shapes, one file per kind: what each is compiled into for
//! the hit loops and the occluders, and, for those that can emit, how a
//! light is sampled on it (`AreaEmitter`).
//! - `sphere`: spheres four to a SIMD group, and a sphere light's cap;
//! - `plane`: infinite planes (found by rays, never sampled);
//! - `triangle`: triangles four to a SIMD group behind a test of where the
//!   ray crosses their plane;
//! - `mesh_light`: a mesh's triangles as one light;
//! - `triangle_set`: the triangles compiled, shared by worlds of the same ones.

pub mod bvh;
pub mod mesh_light;
pub mod plane;
pub mod sphere;
pub mod triangle;
pub mod triangle_set;
pub mod triangle_tree;

use std::sync::Arc;

use glam::{DVec3, Vec2, Vec3};

use crate::geometry::real::{Real, V3};
use crate::geometry::{Ray, SurfaceHit, Triangle};
use crate::scene::mesh::Meshes;
use crate::scene::Shape;
pub use mesh_light::MeshEmitter;
pub use plane::PlaneShape;
use sphere::Sphere;
pub use sphere::{CappedSphere, EmitterCap, SphereLanes, SphereReach, Spheres};
pub use triangle::TriangleLanes;
pub use triangle_set::{TriangleSet, TriangleSource};
pub use triangle_tree::TriangleTree;

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

/// The surface an area light is sampled on: the shape, with what each
/// kind answers as a light in its own file (`AreaEmitter`).
#[derive(Clone, Debug)]
pub enum Emitter {
    /// Sphere `sphere` of the world, emitting from its cap.
    Sphere { sphere: u32, shape: CappedSphere },
    /// Triangle `triangle` of the world.
    Triangle { triangle: u32, shape: Triangle },
    /// A mesh's triangles (shared: the light is cloned with the world's lights).
    Mesh(Arc<MeshEmitter>),
}

/// `$body` for the emitter's shape, whatever its kind.
macro_rules! on_shape {
    ($emitter:expr, $shape:ident => $body:expr) => {
        match $emitter {
            Emitter::Sphere { shape: $shape, .. } => $body,
            Emitter::Triangle { shape: $shape, .. } => $body,
            Emitter::Mesh($shape) => $body,
        }
    };
}

impl Emitter {
    /// The emitting area.
    pub fn area(&self) -> f32 {
        on_shape!(self, shape => shape.area())
    }

    /// Whether `point` (on the emitter) lies where it emits: on a sphere,
    /// within its cap.
    pub fn emits_at(&self, point: Vec3) -> bool {
        on_shape!(self, shape => shape.emits_at(point))
    }

    /// Bound on the error of points computed on it.
    #[inline]
    pub fn error(&self) -> f32 {
        on_shape!(self, shape => shape.error())
    }

    /// A point uniform over the emitting area: (point, normal, error bound).
    pub fn uniform_point(&self, u: Vec2) -> (Vec3, Vec3, f32) {
        let (point, normal) = on_shape!(self, shape => shape.uniform_point(u));
        (point, normal, self.error())
    }

    /// A point on it seen from `p`: (point, outward normal, error bound,
    /// solid-angle pdf at `p`).
    #[inline]
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32, f32)> {
        let (point, normal, pdf) = on_shape!(self, shape => shape.sample_from(p, u))?;
        Some((point, normal, self.error(), pdf))
    }

    /// The solid-angle pdf with which `sample_from` draws `hit` from `p`.
    #[inline]
    pub fn pdf_from(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        on_shape!(self, shape => shape.pdf_from(p, hit))
    }

    /// Whether every point it emits from lies in a region
    /// (`AreaEmitter::held_by`).
    pub fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool) -> bool {
        on_shape!(self, shape => shape.held_by(holds))
    }
}

/// Every shape of the world, kind by kind, as the hit loops and the
/// occluders read them. Each kind's arm of what follows is its only
/// mention outside its own file.
#[derive(Clone, Debug, Default)]
pub struct Shapes {
    pub spheres: Spheres,
    pub planes: Vec<PlaneShape>,
    pub triangles: Arc<TriangleSet>,
}

/// Up to how many triangles a ray tests them all, four at a time, rather
/// than find them through a hierarchy.
pub const GROUPED_TRIANGLES: usize = 64;

/// Each triangle's box.
pub(super) fn triangle_boxes(triangles: &[(Triangle, u32)]) -> Vec<(Vec3, Vec3)> {
    (triangles.iter())
        .map(|(t, _)| {
            let [a, b, c] = t.vertices;
            (a.min(b.min(c)), a.max(b.max(c)))
        })
        .collect()
}

/// Where each kind starts when every shape is counted once, kind by kind in
/// `ShapeRef`'s order: the index the lanes carry from a hit to its surface.
#[derive(Clone, Copy, Debug)]
pub struct ShapeIndex {
    pub first_plane: u32,
    pub first_triangle: u32,
}

impl Shapes {
    /// Of the objects' `shapes` (in order, the object's index beside each),
    /// and where each one went.
    pub fn new<'s>(shapes: impl Iterator<Item = (&'s Shape, u32)>, meshes: &Meshes) -> (Self, Vec<ShapeRef>) {
        let (mut spheres, mut planes, mut sources) = (Vec::new(), Vec::new(), Vec::new());
        // Each source's mesh triangles as its file gives them (none for a triangle)
        let mut files: Vec<&[[Vec3; 3]]> = Vec::new();
        let mut triangles = 0;
        let refs = shapes
            .map(|(shape, object)| match *shape {
                Shape::Sphere { center, radius } => {
                    spheres.push(Sphere { center, radius, object });
                    ShapeRef::Sphere(spheres.len() as u32 - 1)
                }
                Shape::Plane { point, normal } => {
                    let normal = normal.normalize();
                    planes.push(PlaneShape { normal, offset: normal.dot(point), object });
                    ShapeRef::Plane(planes.len() as u32 - 1)
                }
                Shape::Triangle { a, b, c } => {
                    sources.push(TriangleSource::triangle([a, b, c], object));
                    files.push(&[]);
                    triangles += 1;
                    ShapeRef::Triangle(triangles - 1)
                }
                Shape::Mesh { ref file, .. } => {
                    // A valid scene has every mesh it names loaded
                    let loaded = meshes.get(file).map_or(&[][..], |mesh| &mesh.triangles[..]);
                    let key = meshes.get(file).map_or(0, |mesh| mesh.key);
                    let (count, placement) = (loaded.len(), shape.placement());
                    sources.push(TriangleSource::mesh(key, count, placement, object));
                    files.push(loaded);
                    let first = triangles;
                    triangles += count as u32;
                    ShapeRef::Mesh { first, count: count as u32 }
                }
            })
            .collect();
        let list = || {
            let mut list = Vec::with_capacity(triangles as usize);
            for (source, file) in sources.iter().zip(&files) {
                source.make_into(file, &mut list);
            }
            list
        };
        let triangles = TriangleSet::shared(&sources, list);
        (Shapes { spheres: Spheres::new(spheres), planes, triangles }, refs)
    }

    /// The nearest triangle on the ray within (0, t_max), its object and
    /// the hit: what `intersect_triangle` over the triangles finds.
    #[inline]
    pub fn nearest_triangle(&self, ray: &Ray, t_max: f32) -> Option<(u32, u32, SurfaceHit)> {
        let set = &*self.triangles;
        match &set.tree {
            Some(tree) => tree.nearest(|i| &set.list[i as usize].0, ray, t_max),
            None => set.lanes.nearest(&set.list, ray, t_max),
        }
    }

    /// Whether any triangle but those `skip` names lies on the ray within
    /// (0, t_max).
    #[inline]
    pub fn any_triangle(&self, ray: &Ray, t_max: f32, skip: impl Fn(u32) -> bool) -> bool {
        let set = &*self.triangles;
        match &set.tree {
            Some(tree) => tree.any_hit(|i| &set.list[i as usize].0, ray, t_max, skip),
            None => set.lanes.any_hit(&set.list, ray, t_max, skip),
        }
    }

    /// The box about every finite shape (`None` without any): (low, high).
    pub fn finite_box(&self) -> Option<(Vec3, Vec3)> {
        let spheres = self.spheres.list.iter().map(|s| (s.center - s.radius, s.center + s.radius));
        let (lo, hi) = (spheres.chain(triangle_boxes(&self.triangles.list)))
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), (l, h)| (lo.min(l), hi.max(h)));
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// The shape as an area light, where it can be one: an infinite plane
    /// cannot be sampled, nor a degenerate triangle.
    pub fn emitter(&self, shape: ShapeRef) -> Option<Emitter> {
        match shape {
            ShapeRef::Sphere(i) => {
                let Sphere { center, radius, .. } = self.spheres.list[i as usize];
                Some(Emitter::Sphere { sphere: i, shape: CappedSphere { center, radius, cap: EmitterCap::WHOLE } })
            }
            ShapeRef::Triangle(t) => {
                let triangle = self.triangles.list[t as usize].0;
                (!triangle.is_degenerate()).then_some(Emitter::Triangle { triangle: t, shape: triangle })
            }
            ShapeRef::Mesh { first, count } => {
                let triangles: Vec<Triangle> =
                    self.triangles.list[first as usize..(first + count) as usize].iter().map(|(t, _)| *t).collect();
                MeshEmitter::new(&triangles).map(|mesh| Emitter::Mesh(Arc::new(mesh)))
            }
            ShapeRef::Plane(_) => None,
        }
    }

    /// A ball about a finite shape (`None` for a plane): (centre, radius).
    pub fn bounding_ball(&self, shape: ShapeRef) -> Option<(Vec3, f32)> {
        match shape {
            ShapeRef::Sphere(i) => Some((self.spheres.center(i as usize), self.spheres.radius(i as usize))),
            ShapeRef::Triangle(t) => {
                let [a, b, c] = self.triangles.list[t as usize].0.vertices;
                let center = (a + b + c) / 3.0;
                let radius = (a - center).length().max((b - center).length()).max((c - center).length());
                Some((center, radius * 1.001))
            }
            ShapeRef::Mesh { first, count } => {
                let triangles = &self.triangles.list[first as usize..(first + count) as usize];
                let (lo, hi) = (triangle_boxes(triangles).into_iter())
                    .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), (l, h)| (lo.min(l), hi.max(h)));
                (lo.x <= hi.x).then(|| ((lo + hi) * 0.5, (hi - lo).length() * 0.5 * 1.001))
            }
            ShapeRef::Plane(_) => None,
        }
    }

    /// Where each kind starts in the count of every shape (`ShapeIndex`).
    pub fn index(&self) -> ShapeIndex {
        let first_plane = self.spheres.len() as u32;
        ShapeIndex { first_plane, first_triangle: first_plane + self.planes.len() as u32 }
    }

    /// Each shape's object, in `index`'s order.
    pub fn objects(&self) -> impl Iterator<Item = u32> + '_ {
        let spheres = self.spheres.list.iter().map(|sphere| sphere.object);
        let planes = self.planes.iter().map(|plane| plane.object);
        spheres.chain(planes).chain(self.triangles.list.iter().map(|(_, object)| *object))
    }
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

/// Which kind an object's shape is, and where in its kind's list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeRef {
    Sphere(u32),
    Plane(u32),
    Triangle(u32),
    /// A mesh's `count` triangles from `first` on.
    Mesh {
        first: u32,
        count: u32,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct ObjectInfo {
    pub shape: ShapeRef,
    pub material: u32,
    /// Index into `World::lights` when the object is a sampled area light.
    pub light: Option<u32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// A sphere emits only from its cap (light samples land nowhere else,
    /// so a hit elsewhere must get no light pdf), and from all of it when
    /// whole; a triangle from all of it.
    #[test]
    fn an_emitter_emits_from_its_cap_only() {
        let (center, radius) = (Vec3::new(0.5, 2.0, -1.0), 2.0);
        let cap = EmitterCap::in_half_space(center, radius, Vec3::Y, 1.0); // y > 1: 1 − cos θ = 1.5
        let sphere = Emitter::Sphere { sphere: 0, shape: CappedSphere { center, radius, cap } };
        let on = |theta: f32| center + radius * Vec3::new(theta.sin(), theta.cos(), 0.0);
        // cos θ ≥ −0.5: θ up to 120°
        for (degrees, emits) in [(0.0, true), (60.0, true), (115.0, true), (125.0, false), (180.0, false)] {
            assert_eq!(sphere.emits_at(on(f32::to_radians(degrees))), emits, "θ = {degrees}°");
        }
        let whole = Emitter::Sphere { sphere: 0, shape: CappedSphere { center, radius, cap: EmitterCap::WHOLE } };
        assert!(whole.emits_at(on(std::f32::consts::PI)));
        assert!((sphere.area() - 2.0 * std::f32::consts::PI * 4.0 * 1.5).abs() < 1e-4);
        let shape = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let triangle = Emitter::Triangle { triangle: 0, shape };
        assert!(triangle.emits_at(Vec3::new(0.25, 0.25, 0.0)));
        assert_eq!(triangle.area(), 0.5);
    }

    /// The error bound of an emitter covers how far the points drawn on it
    /// lie from its surface, measured in f64 (and they do stray: the bound
    /// is needed): on smallpt's light, radius 600 with its centre near 700,
    /// whole and cut, a small sphere far from the origin, and a triangle.
    #[test]
    fn emitter_points_lie_within_their_error_bound() {
        let mut sampler = Sampler::new(5, 0, 11);
        let mut check = |emitter: Emitter, distance: &dyn Fn(Vec3) -> f64| {
            let mut worst = 0.0f64;
            for _ in 0..20_000 {
                let (point, _, error) = emitter.uniform_point(sampler.next_2d());
                let off = distance(point);
                assert!(off <= error as f64, "{emitter:?}: {point} lies {off:e} off, bound {error:e}");
                worst = worst.max(off);
            }
            assert!(worst > 0.0, "{emitter:?}: every point exact");
        };
        for (center, radius) in [(Vec3::new(50.0, 681.33, 81.6), 600.0), (Vec3::new(-300.0, 2.0, 1000.0), 0.125)] {
            let cut = EmitterCap::in_half_space(center, radius, Vec3::Y, center.y - 0.5 * radius);
            for cap in [EmitterCap::WHOLE, cut] {
                let sphere = Emitter::Sphere { sphere: 0, shape: CappedSphere { center, radius, cap } };
                check(sphere, &|p| ((p.as_dvec3() - center.as_dvec3()).length() - radius as f64).abs());
            }
        }
        let [a, b, c] = [Vec3::new(-40.0, 3.0, 7.5), Vec3::new(-39.0, 3.5, 7.0), Vec3::new(-40.5, 4.0, 8.0)];
        let normal = (b - a).as_dvec3().cross((c - a).as_dvec3()).normalize();
        let triangle = Emitter::Triangle { triangle: 0, shape: Triangle::new(a, b, c) };
        check(triangle, &|p| normal.dot(p.as_dvec3() - a.as_dvec3()).abs());
    }
}
