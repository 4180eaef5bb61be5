//! A world's triangles compiled for rays — the list, and its four-wide
//! groups or its hierarchy — shared by every world made of the same
//! triangles. The studio builds a world for each pane and one for picking
//! at every edit; an edit that leaves the triangles as they were (the
//! camera moved, a colour changed, a sphere added after them) now finds
//! the set already built, where each world built its own hierarchy again.

use std::sync::{Arc, Mutex, Weak};

use glam::{Affine3A, Vec3};

use super::triangle::TriangleLanes;
use super::triangle_tree::TriangleTree;
use super::GROUPED_TRIANGLES;
use crate::geometry::Triangle;

#[derive(Debug, Default)]
pub struct TriangleSet {
    /// Every triangle and its object, in the scene's order.
    pub list: Vec<(Triangle, u32)>,
    /// The same triangles four to a SIMD group, for the hit loops, in a
    /// scene of a few of them.
    pub(crate) lanes: TriangleLanes,
    /// A hierarchy over them, for a scene of many (`GROUPED_TRIANGLES`).
    pub(crate) tree: Option<Arc<TriangleTree>>,
}

/// One object's part of a world's triangles, as the scene gives it: the
/// whole of what a set is made from, compared bit for bit before one is
/// reused (−0 and 0 can round differently).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TriangleSource {
    Triangle {
        vertices: [u32; 9],
        object: u32,
    },
    /// A mesh by its content's key and length, and where it is placed.
    Mesh {
        key: u64,
        triangles: usize,
        placement: [u32; 12],
        object: u32,
    },
}

impl TriangleSource {
    pub fn triangle([a, b, c]: [Vec3; 3], object: u32) -> Self {
        let vertices = [a, b, c].map(|v| v.to_array()).concat();
        TriangleSource::Triangle { vertices: std::array::from_fn(|k| vertices[k].to_bits()), object }
    }

    pub fn mesh(key: u64, triangles: usize, placement: Affine3A, object: u32) -> Self {
        TriangleSource::Mesh { key, triangles, placement: placement.to_cols_array().map(f32::to_bits), object }
    }

    /// What the source names, placed: a triangle's corners, or a mesh's
    /// triangles from its file (`file`) where the placement puts them.
    pub fn triangles<'a>(&self, file: &'a [[Vec3; 3]]) -> Box<dyn Iterator<Item = [Vec3; 3]> + 'a> {
        match *self {
            TriangleSource::Triangle { vertices, .. } => {
                let v = |k: usize| Vec3::from_array(std::array::from_fn(|i| f32::from_bits(vertices[3 * k + i])));
                Box::new(std::iter::once([v(0), v(1), v(2)]))
            }
            TriangleSource::Mesh { placement, .. } => {
                let placement = Affine3A::from_cols_array(&placement.map(f32::from_bits));
                Box::new(file.iter().map(move |t| t.map(|v| placement.transform_point3(v))))
            }
        }
    }

    pub fn object(&self) -> u32 {
        match *self {
            TriangleSource::Triangle { object, .. } | TriangleSource::Mesh { object, .. } => object,
        }
    }
}

/// The sets built so far that some world still holds.
static BUILT: Mutex<Vec<(Vec<TriangleSource>, Weak<TriangleSet>)>> = Mutex::new(Vec::new());

impl TriangleSet {
    /// The set of `list` (the triangles `sources` make), with their planes
    /// shared where they lie in one.
    pub fn new(mut list: Vec<(Triangle, u32)>) -> Self {
        Triangle::share_planes(&mut list.iter_mut().map(|(triangle, _)| triangle).collect::<Vec<_>>());
        match list.len() > GROUPED_TRIANGLES {
            true => {
                TriangleSet { tree: Some(Arc::new(TriangleTree::new(&list))), lanes: TriangleLanes::default(), list }
            }
            false => TriangleSet { lanes: TriangleLanes::new(&list), tree: None, list },
        }
    }

    /// The set `sources` make: one a world still holds if there is one,
    /// else `list()`'s, built here (outside the lock: worlds of other
    /// triangles are not kept waiting) and kept for the next world.
    pub fn shared(sources: &[TriangleSource], list: impl FnOnce() -> Vec<(Triangle, u32)>) -> Arc<Self> {
        // An empty set is not worth a lookup
        if sources.is_empty() {
            return Arc::new(TriangleSet::default());
        }
        if let Some(set) = Self::find(sources) {
            return set;
        }
        let set = Arc::new(TriangleSet::new(list()));
        let mut built = BUILT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        built.retain(|(_, set)| set.strong_count() > 0);
        // Built meanwhile by another world's thread: the first one stays
        if let Some(first) = built.iter().find(|(s, _)| *s == sources).and_then(|(_, set)| set.upgrade()) {
            return first;
        }
        built.push((sources.to_vec(), Arc::downgrade(&set)));
        set
    }

    fn find(sources: &[TriangleSource]) -> Option<Arc<Self>> {
        let built = BUILT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        built.iter().find(|(s, _)| s == sources).and_then(|(_, set)| set.upgrade())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::World;
    use crate::scene::{presets, Scene, Shape, ValidScene};

    fn world(scene: &Scene) -> World {
        World::new(&ValidScene::new(scene.clone()).expect("a valid scene"))
    }

    /// Worlds of the same triangles share one set; a camera moved, a
    /// colour changed or a sphere added do not build it again, while a mesh
    /// moved, a triangle's corner moved by one ulp, or the objects
    /// renumbered do.
    #[test]
    fn worlds_of_the_same_triangles_share_one_set() {
        for name in ["knot", "cornell-mesh"] {
            let scene = presets::preset(name).expect("a preset").expect("it loads").into_scene();
            let first = world(&scene);
            let mut edited = scene.clone();
            edited.camera.position.x += 0.5;
            edited.materials[0].model = crate::scene::MaterialModel::Lambert { albedo: glam::Vec3::splat(0.2) };
            edited.objects.push(crate::scene::Object {
                name: "ball".into(),
                shape: Shape::Sphere { center: glam::Vec3::ONE, radius: 0.1 },
                material: edited.materials[0].name.clone(),
            });
            let again = world(&edited);
            assert!(Arc::ptr_eq(&first.shapes.triangles, &again.shapes.triangles), "{name}: built again");

            let mesh = scene.objects.iter().position(|o| matches!(o.shape, Shape::Mesh { .. })).expect("a mesh");
            let mut moved = scene.clone();
            let Shape::Mesh { translate, .. } = &mut moved.objects[mesh].shape else { unreachable!() };
            translate.y += 0.01;
            let mut renumbered = scene.clone();
            renumbered.objects.swap(0, mesh.max(1));
            let mut signed = scene.clone();
            let panel = signed.objects.iter_mut().find(|o| matches!(o.shape, Shape::Triangle { .. })).expect("a panel");
            let Shape::Triangle { a, .. } = &mut panel.shape else { unreachable!() };
            a.x = a.x.next_up();
            for (what, other) in [("a moved mesh", moved), ("renumbered objects", renumbered), ("a corner", signed)] {
                let other = world(&other);
                assert!(!Arc::ptr_eq(&first.shapes.triangles, &other.shapes.triangles), "{name}: {what} shared");
            }
        }
    }
}
