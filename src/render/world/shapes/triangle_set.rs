//! A world's triangles compiled for rays — the list, and its four-wide
//! groups or its hierarchy — shared by every world made of the same
//! triangles. The studio builds a world for each pane and one for picking
//! at every edit; an edit that leaves the triangles as they were (the
//! camera moved, a colour changed, a sphere added after them) now finds
//! the set already built, where each world built its own hierarchy again.

use std::cell::Cell;
use std::sync::{Arc, Mutex, OnceLock, Weak};

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

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

    /// Appends to `list` the triangles the source makes: a triangle, or a
    /// mesh's triangles from its file (`file`) where the placement puts
    /// them (made on every thread: a million of them take a while).
    pub fn make_into(&self, file: &[[Vec3; 3]], list: &mut Vec<(Triangle, u32)>) {
        let object = self.object();
        match *self {
            TriangleSource::Triangle { vertices, .. } => {
                let v = |k: usize| Vec3::from_array(std::array::from_fn(|i| f32::from_bits(vertices[3 * k + i])));
                list.push((Triangle::new(v(0), v(1), v(2)), object));
            }
            TriangleSource::Mesh { placement, .. } => {
                let placement = Affine3A::from_cols_array(&placement.map(f32::from_bits));
                list.par_extend(file.par_iter().map(|t| {
                    let [a, b, c] = t.map(|v| placement.transform_point3(v));
                    (Triangle::new(a, b, c), object)
                }));
            }
        }
    }

    pub fn object(&self) -> u32 {
        match *self {
            TriangleSource::Triangle { object, .. } | TriangleSource::Mesh { object, .. } => object,
        }
    }
}

/// A set being built or built: those waiting for it wait on the lock,
/// which then holds it as long as some world does.
type Slot = Arc<OnceLock<Weak<TriangleSet>>>;

/// The sets built or being built, by what makes them.
static BUILT: Mutex<Vec<(Vec<TriangleSource>, Slot)>> = Mutex::new(Vec::new());

thread_local! {
    /// Whether this thread is building a set (`shared`).
    static BUILDING: Cell<bool> = const { Cell::new(false) };
}

/// This thread's building, until dropped (a panicking build too).
struct Building;

impl Building {
    fn start() -> Self {
        BUILDING.set(true);
        Building
    }
}

impl Drop for Building {
    fn drop(&mut self) {
        BUILDING.set(false);
    }
}

impl TriangleSet {
    /// The set of `list`, its triangles' planes shared where they lie in
    /// one, grouped or under a hierarchy by their number.
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
    /// or the one another thread is building (waited for: the studio's
    /// panes and its picking ask for the same set at once, and built it
    /// once each), else `list()`'s, built here and kept for the next world.
    pub fn shared(sources: &[TriangleSource], list: impl Fn() -> Vec<(Triangle, u32)>) -> Arc<Self> {
        // An empty set is not worth a lookup; and a thread that is building
        // a set, waiting in one of the build's parallel loops, may be handed
        // another task that asks for a set: it must not wait for itself
        if sources.is_empty() || BUILDING.get() {
            return Arc::new(TriangleSet::new(list()));
        }
        let slot = {
            let mut built = BUILT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            // Those built and no longer held go; those being built stay
            built.retain(|(_, slot)| slot.get().is_none_or(|set| set.strong_count() > 0));
            match built.iter().find(|(s, _)| s == sources) {
                Some((_, slot)) => slot.clone(),
                None => {
                    let slot = Slot::default();
                    built.push((sources.to_vec(), slot.clone()));
                    slot
                }
            }
        };
        // Outside the lock: worlds of other triangles are not kept waiting
        let mut mine = None;
        let set = slot.get_or_init(|| {
            let _building = Building::start();
            let set = Arc::new(TriangleSet::new(list()));
            let held = Arc::downgrade(&set);
            mine = Some(set);
            held
        });
        // Built by this thread, or still held by another's world; or, rarely,
        // let go between the lookup and here: built again, not kept
        mine.or_else(|| set.upgrade()).unwrap_or_else(|| Arc::new(TriangleSet::new(list())))
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

    /// Threads asking for the same new set at once (the studio's panes
    /// after an edit) wait for one build and share it.
    #[test]
    fn a_set_asked_for_at_once_is_built_once() {
        let builds = std::sync::atomic::AtomicUsize::new(0);
        let sources = [TriangleSource::triangle([glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z * 7.25], 3)];
        let list = || {
            builds.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            // Long enough that the other threads ask while it is built
            std::thread::sleep(std::time::Duration::from_millis(50));
            vec![(Triangle::new(glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z * 7.25), 3)]
        };
        let sets: Vec<Arc<TriangleSet>> = std::thread::scope(|scope| {
            let threads: Vec<_> = (0..4).map(|_| scope.spawn(|| TriangleSet::shared(&sources, list))).collect();
            threads.into_iter().map(|t| t.join().expect("a thread")).collect()
        });
        assert_eq!(builds.into_inner(), 1);
        assert!(sets.iter().all(|set| Arc::ptr_eq(set, &sets[0])));
    }

    /// A thread building a set may be handed, inside the build's parallel
    /// loops, a task that asks for the same set: it builds its own rather
    /// than wait for itself (which never ends).
    #[test]
    fn a_thread_building_a_set_does_not_wait_for_itself() {
        let sources = [TriangleSource::triangle([glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z * 9.5], 1)];
        let plain = || vec![(Triangle::new(glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z * 9.5), 1)];
        let asked_again = || TriangleSet::shared(&sources, plain).list.clone();
        let set = TriangleSet::shared(&sources, asked_again);
        assert_eq!(set.list.len(), 1);
        // Its building over, the thread finds the set again
        assert!(Arc::ptr_eq(&set, &TriangleSet::shared(&sources, plain)));
    }
}
