//! The scene compiled for rendering: shapes in flat arrays (spheres as a
//! structure of arrays for the nearest-hit loop), materials and lights
//! resolved to indices, disabled lights dropped.

pub mod alias;
pub mod camera;
pub mod emission;
pub mod lane_world;
pub(crate) mod lanes;
pub mod light;
pub mod materials;
pub mod occluders;
pub mod rng;
pub mod sampling;
pub mod shapes;

use glam::Vec3;

use crate::geometry::real::V3;
use crate::geometry::sphere::{wall_exit, wall_exit_hit, wall_slack, AnchoredSphere};
use crate::geometry::{plane_exit_t, plane_hit, plane_t, sphere_hit};
use crate::geometry::{Ray, SurfaceHit};
use crate::scene::{MaterialModel, Rgb, ValidScene};
use camera::CameraModel;
use light::{Emitter, LightSource};
use occluders::{Occluders, Shadow, WallPlane, Walls};
use shapes::sphere::Sphere;
use shapes::{EmitterCap, SphereReach};
pub use shapes::{ObjectInfo, PlaneShape, ShapeRef, Shapes, Spheres};

/// What `intersect_held` found nearest.
/// What `World::reach` gives a ray to meet.
struct Reach<'w> {
    spheres: SphereReach<'w>,
    wall_spheres: &'w [(u32, AnchoredSphere)],
    planes: &'w [PlaneShape],
    wall_planes: &'w [WallPlane],
}

enum Inside<'w> {
    /// Sphere `i` of the world, entered (near root) or left.
    Sphere(u32, bool),
    /// Wall sphere `k` of `Walls::wall_spheres`, left.
    Wall(usize),
    Plane(&'w PlaneShape),
    /// A triangle of this object.
    Triangle(u32),
}

#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub surface: SurfaceHit,
    pub object: u32,
    pub material: u32,
}

#[derive(Clone, Debug)]
pub struct World {
    pub shapes: Shapes,
    pub objects: Vec<ObjectInfo>,
    pub materials: Vec<MaterialModel>,
    pub lights: Vec<LightSource>,
    pub background: Rgb,
    pub ambient: Rgb,
    /// Where photons must go: a sphere around everything finite (planes
    /// excluded), or around what the camera sees once `cover` was called.
    pub bounds_center: Vec3,
    pub bounds_radius: f32,
    /// The same as a box, tight about them (`bounds`, `seen_bounds`).
    region: emission::Bounds,
    /// How much wider than `region` photons must start: half again once
    /// `cover`ed, for light that bounces in from just outside the view.
    region_margin: f32,
    /// Spheres and planes that shadow rays from inside may skip (see `Occluders`).
    pub(crate) walls: Walls,
    /// Per triangle, the first light triangle whose plane holds it, if any
    /// (`u32::MAX` if none): shadow rays toward a light skip its plane.
    pub(crate) light_plane: Vec<u32>,
}

/// `points`' box (None without points).
fn bounding_box(points: &[Vec3]) -> Option<emission::Bounds> {
    let (lo, hi) = points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (lo.x <= hi.x).then_some(emission::Bounds { lo, hi })
}

/// A ball about `points`' box, half again as wide: (centre, radius).
fn bounding_ball(points: &[Vec3]) -> Option<(Vec3, f32)> {
    bounding_box(points).map(ball_about)
}

/// The ball about `bounds`, half again as wide: (centre, radius).
fn ball_about(emission::Bounds { lo, hi }: emission::Bounds) -> (Vec3, f32) {
    ((lo + hi) * 0.5, (hi - lo).length() * 0.75)
}

/// The visible points that say how large the scene is: all of them, but
/// where the farthest tenth would more than triple the region, those are
/// left out. A ground plane seen to the horizon puts a few of them hundreds
/// of units off; a region that size spread an infinite light's photons a
/// thousand times too thin over what is seen, and made merge radii, which
/// are fractions of the scene's size, a unit wide in a scene of five (the
/// far ground then gets its infinite lights' light from path tracing's
/// strategies alone).
fn region_points(points: Vec<Vec3>) -> Vec<Vec3> {
    let near = nearest_nine_tenths(&points);
    match (bounding_ball(&points), bounding_ball(&near)) {
        (Some(all), Some(few)) if all.1 > 3.0 * few.1 => near,
        _ => points,
    }
}

/// The nine in ten of `points` nearest their median (per axis).
fn nearest_nine_tenths(points: &[Vec3]) -> Vec<Vec3> {
    let median = |axis: usize| {
        let mut values: Vec<f32> = points.iter().map(|p| p[axis]).collect();
        let middle = values.len() / 2;
        match values.len() {
            0 => 0.0,
            _ => *values.select_nth_unstable_by(middle, f32::total_cmp).1,
        }
    };
    let middle = Vec3::new(median(0), median(1), median(2));
    let mut near = points.to_vec();
    near.sort_by(|a, b| (*a - middle).length_squared().total_cmp(&(*b - middle).length_squared()));
    near.truncate(points.len().div_ceil(10) * 9);
    near
}

impl World {
    /// Compile a scene for rendering.
    pub fn new(scene: &ValidScene) -> Self {
        let objects = scene.objects.iter().zip(0..).map(|(object, id)| (&object.shape, id));
        let (shapes, refs) = Shapes::new(objects, &scene.meshes);
        let mut world = World {
            shapes,
            objects: Vec::with_capacity(scene.objects.len()),
            materials: scene.materials.iter().map(|m| m.model.clone()).collect(),
            lights: Vec::new(),
            background: scene.background,
            ambient: scene.ambient,
            bounds_center: Vec3::ZERO,
            bounds_radius: 0.0,
            region: emission::Bounds { lo: Vec3::ZERO, hi: Vec3::ZERO },
            region_margin: 1.0,
            walls: Walls::default(),
            light_plane: Vec::new(),
        };
        for (object, shape) in scene.objects.iter().zip(refs) {
            let material = scene.material_index(&object.material).unwrap_or(0) as u32;
            world.objects.push(ObjectInfo { shape, material, light: None });
        }
        if let Some((lo, hi)) = world.shapes.finite_box() {
            world.bounds_center = (lo + hi) * 0.5;
            world.bounds_radius = (hi - lo).length() * 0.5;
            world.region = emission::Bounds { lo, hi };
        }
        // Disabled lights are simply absent from the render
        world.lights.extend(scene.lights.iter().filter(|l| l.enabled).map(LightSource::of));
        // Emissive spheres and triangles become sampled area lights; an
        // emissive infinite plane cannot be sampled and is only found by rays.
        for index in 0..world.objects.len() {
            let info = world.objects[index];
            if let MaterialModel::Emissive { radiance } = world.materials[info.material as usize] {
                let emitter = world.shapes.emitter(info.shape).filter(|_| radiance.max_element() > 0.0);
                if let Some(emitter) = emitter {
                    world.objects[index].light = Some(world.lights.len() as u32);
                    world.lights.push(LightSource::Area(light::AreaLight { object: index as u32, radiance, emitter }));
                }
            }
        }
        // The background lights the scene from every direction
        if scene.background.max_element() > 0.0 {
            world.lights.push(LightSource::Background(light::BackgroundLight { radiance: scene.background }));
        }
        let light_triangles: Vec<u32> = (world.lights.iter())
            .filter_map(|light| match light {
                LightSource::Area(light::AreaLight { emitter: Emitter::Triangle { triangle, .. }, .. }) => {
                    Some(*triangle)
                }
                _ => None,
            })
            .collect();
        let triangles = &world.shapes.triangles.list;
        world.light_plane = (triangles.iter())
            .map(|(t, _)| {
                let holds = |&j: &u32| triangles[j as usize].0.holds_in_plane(t);
                light_triangles.iter().copied().find(holds).unwrap_or(u32::MAX)
            })
            .collect();
        world.fit_caps(None);
        world
    }

    /// Nearest hit in (0, t_max).
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.intersect_held(ray, t_max, false)
    }

    /// What a ray meets from where it starts: every sphere and plane, or,
    /// for a path held inside every wall, the spheres and planes that are
    /// not walls, and the walls from inside.
    #[inline]
    fn reach(&self, held: bool) -> Reach<'_> {
        let walls = &self.walls;
        match held {
            true => Reach {
                spheres: SphereReach::Groups(&walls.spheres),
                wall_spheres: &walls.wall_spheres,
                planes: &walls.planes,
                wall_planes: &walls.wall_planes,
            },
            false => Reach {
                spheres: SphereReach::All(&self.shapes.spheres),
                wall_spheres: &[],
                planes: &self.shapes.planes,
                wall_planes: &[],
            },
        }
    }

    /// Whether a path starting at `origin` is inside every wall (see
    /// `Walls`): its shadow rays skip them, its rays meet them only on
    /// their way out.
    #[inline]
    pub fn holds(&self, origin: Vec3) -> bool {
        self.walls.hold(origin)
    }

    /// What can block the shadow rays of a path `held` inside every wall or not.
    #[inline]
    pub fn occluders(&self, held: bool) -> Occluders<'_> {
        Occluders::for_path(&self.walls, &self.shapes, &self.light_plane, held)
    }

    /// Whether anything blocks `shadow` (tested against what can block it
    /// from where it starts, `occluders`).
    #[inline]
    pub fn blocked(&self, shadow: &Shadow) -> bool {
        self.occluders(shadow.held).blocks_shadow(shadow)
    }

    /// `intersect` for a path `held` inside every wall (`holds` of where it
    /// started): it meets the walls only on their way out, and at once
    /// where rounding has put it just outside one (at the seam of two
    /// walls, whose hits lie within each other's error), so it never
    /// leaves the room.
    #[inline]
    pub fn intersect_held(&self, ray: &Ray, t_max: f32, held: bool) -> Option<Hit> {
        let reach = self.reach(held);
        let s = &self.shapes.spheres;
        let mut best_t = t_max;
        let mut best = None;
        if let Some((i, t, near)) = reach.spheres.nearest(ray, best_t) {
            best_t = t;
            best = Some(Inside::Sphere(i, near));
        }
        let (origin, direction) = (V3::from(ray.origin), V3::from(ray.direction));
        for (k, (_, wall)) in reach.wall_spheres.iter().enumerate() {
            let (anchor, normal) = (V3::from(wall.anchor), V3::from(wall.normal));
            let (t, hit) = wall_exit(origin, direction, anchor, normal, wall.radius, best_t);
            if hit {
                best_t = t;
                best = Some(Inside::Wall(k));
            }
        }
        for plane in reach.planes {
            if let Some(t) = plane_t(ray, plane.normal, plane.offset, best_t) {
                best_t = t;
                best = Some(Inside::Plane(plane));
            }
        }
        for wall in reach.wall_planes {
            if let Some(t) = plane_exit_t(ray, wall.inward, wall.offset, best_t) {
                best_t = t;
                best = Some(Inside::Plane(&wall.plane));
            }
        }
        let triangle_hit = self.shapes.nearest_triangle(ray, best_t);
        if let Some((_, object, hit)) = triangle_hit {
            best_t = hit.t;
            best = Some(Inside::Triangle(object));
        }
        let (surface, object) = match best? {
            Inside::Sphere(i, near) => {
                let Sphere { center, radius, object } = s.list[i as usize];
                (sphere_hit(ray, center, radius, best_t, near), object)
            }
            Inside::Wall(k) => {
                let (i, wall) = &reach.wall_spheres[k];
                let center = V3::from(s.center(*i as usize));
                let (point, normal, error) = wall_exit_hit(origin, direction, best_t, center, wall_slack(wall));
                let surface = SurfaceHit { t: best_t, point: point.into(), normal: normal.into(), error };
                (surface, s.list[*i as usize].object)
            }
            Inside::Plane(plane) => (plane_hit(ray, plane.normal, plane.offset, best_t), plane.object),
            Inside::Triangle(object) => (triangle_hit?.2, object),
        };
        Some(Hit { surface, object, material: self.objects[object as usize].material })
    }

    /// Whether anything lies on the ray in (0, t_max): shadow rays stop at the
    /// first blocker.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        SphereReach::All(&self.shapes.spheres).any_hit_except(ray, t_max, None)
            || self.shapes.planes.iter().any(|p| plane_t(ray, p.normal, p.offset, t_max).is_some())
            || self.shapes.any_triangle(ray, t_max, |_| false)
    }

    /// The world as a render through `camera` at width × height uses it
    /// (`cover`ed by what the camera sees), and the size of what it sees
    /// (`visible_radius`, or the bounds' where it sees nothing).
    pub fn for_view(scene: &ValidScene, camera: &CameraModel, width: u32, height: u32) -> (World, f32) {
        let mut world = World::new(scene);
        let visible = region_points(world.visible_points(camera, width, height));
        world.cover(&visible, camera);
        let radius = World::visible_radius(&visible).unwrap_or(world.bounds_radius.max(1.0));
        (world, radius)
    }

    /// First hits of a grid of primary rays: where the camera looks.
    pub fn visible_points(&self, camera: &CameraModel, width: u32, height: u32) -> Vec<Vec3> {
        const GRID: u32 = 16;
        (0..GRID * GRID)
            .filter_map(|k| {
                let x = ((k % GRID) as f32 + 0.5) / GRID as f32 * width as f32;
                let y = ((k / GRID) as f32 + 0.5) / GRID as f32 * height as f32;
                self.intersect(&camera.pixel_ray(x, y), f32::INFINITY).map(|hit| hit.surface.point)
            })
            .filter(|p| p.is_finite())
            .collect()
    }

    /// The size of what the camera sees: the root-mean-square spread of
    /// `visible_points`. Gather radii are fractions of it; the bounds of all
    /// geometry would not do, since smallpt's walls are spheres of radius 1e5
    /// around a room of 100.
    pub fn visible_radius(points: &[Vec3]) -> Option<f32> {
        if points.len() < 2 {
            return None;
        }
        let mean = points.iter().copied().sum::<Vec3>() / points.len() as f32;
        let rms = (points.iter().map(|p| (*p - mean).length_squared()).sum::<f32>() / points.len() as f32).sqrt();
        (rms.is_finite() && rms > 0.0).then_some(rms)
    }

    /// Make the region infinite lights must light (`bounds`, `seen_bounds`)
    /// and the part of giant emitters photons leave from (the bounding
    /// sphere) what the camera sees, with a margin for light that bounces in
    /// from just outside the view, and fit the emitters' caps to what
    /// `camera` can see.
    /// The bounds of all finite objects would not do when walls are spheres
    /// of radius 1e5.
    /// `points` are what the camera sees (`region_points`).
    pub fn cover(&mut self, points: &[Vec3], camera: &CameraModel) {
        if let Some(region) = bounding_box(points) {
            (self.bounds_center, self.bounds_radius) = ball_about(region);
            (self.region, self.region_margin) = (region, 1.5);
        }
        let eye = camera.central_origin();
        self.fit_caps(Some(eye));
        let opaque = |object: u32| {
            let material = &self.materials[self.objects[object as usize].material as usize];
            !matches!(material, MaterialModel::Glass { .. } | MaterialModel::Emissive { .. })
        };
        self.walls = Walls::find(&self.shapes.spheres, &self.shapes.planes, opaque, &self.lights, eye);
    }

    /// The part of sphere `sphere` that lights the scene, when it is an
    /// emitter (the whole sphere otherwise).
    pub fn emitting_cap(&self, sphere: usize) -> EmitterCap {
        let on_it = |light: &&LightSource| matches!(light, LightSource::Area(light::AreaLight { emitter: Emitter::Sphere { sphere: s, .. }, .. }) if *s as usize == sphere);
        self.lights.iter().find(on_it).and_then(LightSource::cap).unwrap_or(EmitterCap::WHOLE)
    }

    /// Give each sphere light the cap it emits from (`emitter_caps`).
    fn fit_caps(&mut self, eye: Option<Vec3>) {
        let caps = self.emitter_caps(eye);
        for light in &mut self.lights {
            if let LightSource::Area(light::AreaLight { emitter: Emitter::Sphere { sphere, shape }, .. }) = light {
                shape.cap = caps[*sphere as usize];
            }
        }
    }

    /// Each emissive sphere's cap:
    /// - its part inside an opaque sphere, or on the camera's side of an
    ///   opaque plane, that holds the camera (`eye`, where its central ray
    ///   starts), the smallest such part.
    ///   Paths that start inside that wall never leave it, so this is exactly
    ///   what they can see; paths outside it find every light sample blocked
    ///   and get the light through BSDF sampling alone, at full MIS weight.
    ///   smallpt's light pokes 0.27 through the ceiling: 98% of the samples
    ///   drawn on its part near the room landed behind the ceiling;
    /// - otherwise, for a sphere larger than the region the camera sees, its
    ///   part within that region (a guess: light from the rest is left to
    ///   BSDF sampling).
    fn emitter_caps(&self, eye: Option<Vec3>) -> Vec<EmitterCap> {
        let s = &self.shapes.spheres;
        let count = s.len();
        let material = |i: usize| &self.materials[self.objects[s.list[i].object as usize].material as usize];
        let enclosing: Vec<usize> = match eye {
            Some(eye) => (0..count)
                .filter(|&j| !matches!(material(j), MaterialModel::Glass { .. }))
                .filter(|&j| (eye.as_dvec3() - s.center(j).as_dvec3()).length() <= s.radius(j) as f64 * (1.0 - 1e-6))
                .collect(),
            None => Vec::new(),
        };
        // Opaque planes, with the normal of the camera's side
        let sides: Vec<(Vec3, f32, u32)> = match eye {
            Some(eye) => (self.shapes.planes.iter())
                .filter(|p| {
                    let material = &self.materials[self.objects[p.object as usize].material as usize];
                    !matches!(material, MaterialModel::Glass { .. } | MaterialModel::Emissive { .. })
                })
                .filter_map(|p| {
                    let side = (p.normal.dot(eye) - p.offset).signum();
                    (side != 0.0).then_some((p.normal * side, p.offset * side, p.object))
                })
                .collect(),
            None => Vec::new(),
        };
        (0..count)
            .map(|i| {
                if !matches!(material(i), MaterialModel::Emissive { .. }) {
                    return EmitterCap::WHOLE;
                }
                let Sphere { center, radius, .. } = s.list[i];
                let in_spheres = (enclosing.iter().filter(|&&j| j != i)).map(|&j| EmitterCap {
                    wall: Some(s.list[j].object),
                    ..EmitterCap::inside(center, radius, s.center(j), s.radius(j))
                });
                let in_half_spaces = sides.iter().map(|&(inward, offset, object)| EmitterCap {
                    wall: Some(object),
                    ..EmitterCap::in_half_space(center, radius, inward, offset)
                });
                (in_spheres.chain(in_half_spaces))
                    .filter(|cap| !cap.is_whole())
                    .min_by(|a, b| a.one_minus_cos.total_cmp(&b.one_minus_cos))
                    .unwrap_or_else(|| self.region_cap(center, radius))
            })
            .collect()
    }

    /// The part of a sphere larger than the region the camera sees that lies
    /// within it (the whole sphere for smaller ones).
    fn region_cap(&self, center: Vec3, radius: f32) -> EmitterCap {
        let (region, extent) = (self.bounds_center, self.bounds_radius);
        let distance = (region - center).length();
        if radius <= extent || distance <= 0.0 || distance >= radius + extent || distance + radius <= extent {
            return EmitterCap::WHOLE;
        }
        EmitterCap::inside(center, radius, region, extent)
    }

    /// The region infinite lights must light for the photons (`cover`):
    /// what the camera sees, with a margin, since light that bounces in
    /// from outside it is lost to them.
    #[inline]
    pub fn bounds(&self) -> emission::Bounds {
        self.region.grown(self.region_margin)
    }

    /// What the camera sees, without the margin: for light subpaths whose
    /// paths the camera's own subpaths can make too, where light comes from
    /// outside it (multiple importance sampling gives those paths to them).
    #[inline]
    pub fn seen_bounds(&self) -> emission::Bounds {
        self.region
    }

    #[inline]
    pub fn material_of(&self, hit: &Hit) -> &MaterialModel {
        &self.materials[hit.material as usize]
    }

    /// Radiance emitted from a hit toward `wo` (front side only).
    #[inline]
    pub fn emitted(&self, hit: &Hit, wo: Vec3) -> Rgb {
        match self.materials[hit.material as usize] {
            MaterialModel::Emissive { radiance } if hit.surface.normal.dot(wo) > 0.0 => radiance,
            _ => Rgb::ZERO,
        }
    }
}
