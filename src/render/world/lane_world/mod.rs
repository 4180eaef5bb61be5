//! The world compiled for eight rays at a time (`LaneWorld`): shapes as
//! the hit loop meets them, every shape's material, the lights, the
//! occluders. Each sphere, plane and triangle is tested against eight rays
//! in one SIMD pass (a triangle behind a test of where the rays cross its
//! plane, `geometry::cull`). Compiled once per job (`None` on a CPU without
//! AVX2) and read by every algorithm through its stage: the path tracer's
//! bounce (`integrators::path_lanes`), photons in flight, and the subpaths
//! and camera rays that meet the world through its hit loop.
//!
//! What it computes is what the scalar code computes, lane by lane, bit
//! for bit: the same operations in the same order on the same random
//! streams (`tests/path_lanes.rs` checks it). Rare cases call the scalar
//! code for that lane: a ray exactly on a triangle's edge.
//!
//! In `hits` the hit loop, in `shadows` the shadow test; `draws` and
//! `lights` sample in the lanes what the scalar code samples one at a time
//! (the materials' own lanes are `materials::lanes`), and `wall_exits`
//! asks a room of walls where a held ray leaves it.

use std::sync::Arc;

use glam::Vec3;

mod draws;
mod hits;
mod lights;
mod shadows;
mod wall_exits;

pub(crate) use draws::{Given, PickedLight, Want};
use hits::{lane_culls, LaneCull};
pub(crate) use lights::EmittedLanes;
pub(crate) use lights::{LaneLights, LightLanes};
pub(crate) use shadows::Skips;
use wall_exits::WallExits;

use crate::geometry::sphere::{wall_slack, AnchoredSphere};
use crate::render::world::lanes::{self, Column, Column3, Index8, F8, LANES, M8, V8};
use crate::render::world::light::{self, Emitter, LightSource};
pub(crate) use crate::render::world::materials::lanes::{LaneSurfaces, MaterialTable, Scattered};
use crate::render::world::shapes::{sphere::Sphere, ShapeIndex, TriangleSet};
use crate::render::world::{ShapeRef, World};
use crate::scene::Rgb;

/// One sphere, as the hit loop meets it.
#[derive(Clone, Copy, Debug)]
struct SphereInfo {
    center: Vec3,
    radius2: f32,
    /// Its index among the shapes, as the lanes count them.
    shape: f32,
    /// A wall (`occluders::Walls`), about its point nearest the camera:
    /// paths inside every wall meet it only on their way out (`wall_exit`).
    wall: Option<AnchoredSphere>,
}

/// What a sphere's hit is rebuilt from, a column per field, indexed by
/// shape (`LaneWorld::sphere_hits`).
#[derive(Clone, Debug)]
struct SphereColumns {
    center: Column3,
    radius: Column,
    /// 1 for a wall, 0 for any other sphere.
    wall: Column,
    /// Bound on the error of points computed on it (as `sphere_hit` gives).
    error: Column,
    /// A wall's `wall_slack` (0 for any other sphere).
    wall_slack: Column,
}

impl SphereColumns {
    /// For `spheres`, the world's `list` as the hit loop meets them.
    fn new(spheres: &[SphereInfo], list: &[Sphere]) -> Self {
        let column = |field: &dyn Fn(&SphereInfo, f32) -> f32| {
            Column::new(spheres.iter().zip(list).map(|(sphere, s)| field(sphere, s.radius)))
        };
        SphereColumns {
            center: Column3::new(spheres.iter().map(|s| s.center)),
            radius: column(&|_, radius| radius),
            wall: column(&|s, _| s.wall.map_or(0.0, |_| 1.0)),
            error: column(&|s, radius| Sphere::error(s.center, radius)),
            wall_slack: column(&|s, _| s.wall.map_or(0.0, |w| wall_slack(&w))),
        }
    }
}

/// One plane, as the hit loop and shadow rays meet it.
#[derive(Clone, Copy, Debug)]
struct PlaneInfo {
    normal: Vec3,
    offset: f32,
    /// A wall (`occluders::WallPlane`): its inside `inward · x > offset`,
    /// which paths inside every wall leave only through it.
    wall: Option<(Vec3, f32)>,
}

/// A sphere as shadow rays test it.
#[derive(Clone, Copy, Debug)]
struct Occluder {
    center: Vec3,
    radius2: f32,
    /// Its index in the world, if a light lies on it: that light's shadow
    /// rays skip it (`occluders`: they meet it only at their end).
    emitter: Option<u32>,
}

/// What `LaneWorld::nearest` finds for eight rays.
pub(crate) struct LaneHits {
    pub(crate) found: M8,
    pub(crate) t: F8,
    /// The shape hit, counted as `LaneWorld::index` counts: an index into
    /// `surfaces`.
    pub(crate) shape: Index8,
    pub(crate) point: V8,
    /// The geometric normal.
    pub(crate) normal: V8,
    pub(crate) error: F8,
}

/// A world compiled for eight-lane path tracing.
#[derive(Clone, Debug)]
pub struct LaneWorld {
    spheres: Vec<SphereInfo>,
    sphere_columns: SphereColumns,
    planes: Vec<PlaneInfo>,
    /// The planes' normals and offsets, indexed by shape (zeros before
    /// the first plane).
    plane_normals: Column3,
    plane_offsets: Column,
    /// The world's triangles, and its hierarchy over them where it has
    /// one: each lane's ray finds its triangle through it, as the scalar
    /// code does.
    triangles: Arc<TriangleSet>,
    /// What the cull reads of each triangle, in one record: one load
    /// where the triangle and a list of runs beside it took several, each
    /// with its bounds check.
    triangle_culls: Vec<LaneCull>,
    /// Each triangle's light plane (`World::light_plane`): a shadow ray
    /// toward a light on a triangle skips the triangles of its plane.
    triangle_planes: Vec<u32>,
    /// Where each kind starts in the count of every shape (the index a
    /// hit carries to its surface).
    index: ShapeIndex,
    /// Every shape's material, in `index`'s order.
    pub(crate) surfaces: MaterialTable,
    /// Shadow rays test these always, and the walls only for paths not
    /// inside every wall (see `occluders::Walls`).
    others: Vec<Occluder>,
    walls: Vec<Occluder>,
    pub(crate) lights: LaneLights,
    /// The sphere each light lies on, if any.
    pub(crate) light_spheres: Vec<Option<u32>>,
    /// The light plane of the triangle each light lies on, if any.
    pub(crate) light_planes: Vec<Option<u32>>,
    pub(crate) background: Rgb,
    /// The walls, as held rays ask where they leave.
    wall_exits: WallExits,
    /// The spheres that are not walls, which is all a held ray asks of
    /// the spheres but where it leaves them.
    inner_spheres: Vec<SphereInfo>,
}

impl LaneWorld {
    /// For worlds of spheres, planes and triangles on a CPU that runs the
    /// lanes (`None` for a world of none, one of more spheres than they
    /// test one by one, or a CPU without AVX2).
    pub fn new(world: &World) -> Option<Self> {
        // Its methods run AVX2 without asking again. Spheres in a hierarchy
        // (a scene of many) are left to the scalar code, which finds them there
        if !lanes::supported() || world.shapes.spheres.bvh.is_some() {
            return None;
        }
        let s = &world.shapes.spheres;
        let index = world.shapes.index();
        let material = |object: u32| &world.materials[world.objects[object as usize].material as usize];
        let surfaces = MaterialTable::new(world.shapes.objects(), material);
        if surfaces.is_empty() {
            return None;
        }
        let wall = |i: usize| world.walls.wall_spheres.iter().find(|(j, _)| *j as usize == i).map(|(_, w)| *w);
        let spheres: Vec<SphereInfo> = (s.list.iter().enumerate())
            .map(|(i, sphere)| SphereInfo {
                center: sphere.center,
                radius2: sphere.radius * sphere.radius,
                shape: i as f32,
                wall: wall(i),
            })
            .collect();
        let planes: Vec<PlaneInfo> = (world.shapes.planes.iter())
            .map(|plane| PlaneInfo {
                normal: plane.normal,
                offset: plane.offset,
                wall: (world.walls.wall_planes.iter())
                    .find(|wall| wall.plane.object == plane.object)
                    .map(|wall| (wall.inward, wall.offset)),
            })
            .collect();
        let light_planes = (world.lights.iter())
            .map(|light| match *light {
                LightSource::Area(light::AreaLight { emitter: Emitter::Triangle { triangle, .. }, .. }) => {
                    Some(world.light_plane[triangle as usize])
                }
                _ => None,
            })
            .collect();
        // The sphere each light lies on
        let light_spheres: Vec<Option<u32>> = (world.lights.iter())
            .map(|light| match *light {
                LightSource::Area(light::AreaLight { object, .. }) => match world.objects[object as usize].shape {
                    ShapeRef::Sphere(i) => Some(i),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        let occluder = |i: usize| Occluder {
            center: spheres[i].center,
            radius2: spheres[i].radius2,
            emitter: light_spheres.contains(&Some(i as u32)).then_some(i as u32),
        };
        let (walls, others) = (0..spheres.len()).partition::<Vec<_>, _>(|&i| spheres[i].wall.is_some());
        let before_planes = std::iter::repeat_n(None, index.first_plane as usize);
        let by_shape = || before_planes.clone().chain(planes.iter().map(Some));
        let inner_spheres = spheres.iter().filter(|s| s.wall.is_none()).copied().collect();
        Some(LaneWorld {
            index,
            inner_spheres,
            others: others.into_iter().map(occluder).collect(),
            walls: walls.into_iter().map(occluder).collect(),
            sphere_columns: SphereColumns::new(&spheres, &s.list),
            spheres,
            plane_normals: Column3::new(by_shape().map(|p| p.map_or(Vec3::ZERO, |p| p.normal))),
            plane_offsets: Column::new(by_shape().map(|p| p.map_or(0.0, |p| p.offset))),
            planes,
            triangles: world.shapes.triangles.clone(),
            // A hierarchy's triangles are never culled in the lanes
            triangle_culls: match world.shapes.triangles.tree {
                Some(_) => Vec::new(),
                None => lane_culls(&world.shapes.triangles.list),
            },
            triangle_planes: world.light_plane.clone(),
            surfaces,
            lights: LaneLights::new(world),
            light_spheres,
            light_planes,
            background: world.background,
            wall_exits: WallExits::new(&world.walls.wall_spheres),
        })
    }

    /// Whether `radiance` traces eight lanes at once on this CPU (AVX2 on
    /// x86-64), rather than falling back to the scalar tracer.
    pub fn runs_in_lanes() -> bool {
        lanes::supported()
    }

    /// `LightSource::emit` for each lane's light (`pick`, an index into
    /// the world's lights) in the lanes of `mask`, from the draws `u1`, `u2`.
    /// Fast only inlined into code built for AVX2.
    #[inline(always)]
    pub(crate) fn emit(
        &self,
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        u1: (F8, F8),
        u2: (F8, F8),
    ) -> EmittedLanes {
        self.lights.emit(world, pick, mask, u1, u2)
    }
}
