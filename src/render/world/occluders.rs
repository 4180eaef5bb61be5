//! What can block a shadow ray, and what need not be tested.
//! - Walls: a path that starts inside an opaque sphere, or on one side of an
//!   opaque plane, never leaves it; and a segment between two points of a
//!   ball or a half-space stays in it. So when such a wall also holds every
//!   light's sample points (smallpt's six spheres of radius 1e5, the Cornell
//!   box's five planes), the shadow rays of paths from inside skip it.
//! - Triangles in the plane of the light's triangle (its own, the other half
//!   of a quad): a shadow ray ends in that plane and meets it nowhere else.
//! - The light's own sphere: a sample faces the point, and a ball lies behind
//!   its tangent plane there, so the shadow ray meets it only at its end.

use glam::{DVec3, Vec3};

use super::lanes::{F8, M8, V8};
use super::light::{LightSample, LightSource};
use super::shapes::{PlaneShape, Shapes, SphereLanes, SphereReach, Spheres};
use crate::geometry::sphere::AnchoredSphere;
use crate::geometry::Ray;
use crate::geometry::{gamma, plane_t};

/// A region a wall bounds, in f64 for exact inside tests.
#[derive(Clone, Copy, Debug)]
enum Region {
    Ball {
        center: DVec3,
        radius: f64,
        /// Less the bound on the error of its hits: paths start further in.
        start_radius: f64,
        /// The same ball in f32, with squared distances below which a point
        /// is surely inside and above which surely outside (f32's error in
        /// |p − c|² is under 6 ulps; the margin is 16).
        center_f32: Vec3,
        surely_in2: f32,
        surely_out2: f32,
    },
    /// `normal · p > offset`: the side the camera is on.
    HalfSpace { normal: DVec3, offset: f64 },
}

impl Region {
    fn ball(center: Vec3, radius: f32) -> Self {
        let margin = gamma(6) as f64 * (center.abs().max_element() + radius) as f64;
        let start_radius = (radius as f64 - margin).max(0.0);
        let radius2 = start_radius * start_radius;
        Region::Ball {
            center: center.as_dvec3(),
            radius: radius as f64,
            start_radius,
            center_f32: center,
            surely_in2: (radius2 * (1.0 - 1e-6)) as f32,
            surely_out2: (radius2 * (1.0 + 1e-6)) as f32,
        }
    }

    /// Whether the ball (`center`, `reach`) lies in the region, touching
    /// its boundary at most.
    fn holds(&self, center: DVec3, reach: f64) -> bool {
        match *self {
            Region::Ball { center: c, radius, .. } => (center - c).length() + reach <= radius,
            Region::HalfSpace { normal, offset } => normal.dot(center) - offset >= reach,
        }
    }

    /// Inside by more than the wall's hits may err: where a path may start
    /// and be sure to meet the wall (a path from within rounding of it may
    /// pass through).
    fn holds_strictly(&self, p: DVec3) -> bool {
        match *self {
            Region::Ball { center, start_radius, .. } => (p - center).length_squared() < start_radius * start_radius,
            Region::HalfSpace { normal, offset } => {
                normal.dot(p) - offset > gamma(7) as f64 * (p.abs().element_sum() + offset.abs())
            }
        }
    }

    /// `holds_strictly` for an f32 point, in f32 unless it is too close to call.
    #[inline]
    fn holds_strictly_f32(&self, p: Vec3) -> bool {
        if let Region::Ball { center_f32, surely_in2, surely_out2, .. } = *self {
            let distance2 = (p - center_f32).length_squared();
            if distance2 < surely_in2 {
                return true;
            }
            if distance2 > surely_out2 {
                return false;
            }
        }
        self.holds_strictly(p.as_dvec3())
    }
}

/// Walls that shadow rays from inside all of them may skip, and the rest.
/// Paths inside every wall also meet them only on their way out
/// (`World::intersect_held`), so none ever leaves the room.
#[derive(Clone, Debug, Default)]
pub struct Walls {
    regions: Vec<Region>,
    /// The spheres and planes that are not walls.
    pub(crate) spheres: SphereLanes,
    pub(crate) planes: Vec<PlaneShape>,
    /// The walls as intersection tests them: spheres by their index in the
    /// world, about their point nearest the camera; planes with the normal
    /// of the camera's side.
    pub(crate) wall_spheres: Vec<(u32, AnchoredSphere)>,
    pub(crate) wall_planes: Vec<WallPlane>,
}

/// A plane that is a wall: the plane, and `inward · x > offset` its inside.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WallPlane {
    pub plane: PlaneShape,
    pub inward: Vec3,
    pub offset: f32,
}

impl Walls {
    /// Opaque spheres and planes (`opaque` of their object) with `eye`
    /// (where the camera's rays start) strictly inside and every light's
    /// sample points inside; none where a light has samples everywhere (a
    /// directional light).
    pub fn find(
        spheres: &Spheres,
        planes: &[PlaneShape],
        opaque: impl Fn(u32) -> bool,
        lights: &[LightSource],
        eye: Vec3,
    ) -> Self {
        if spheres.bvh.is_some() {
            // A room's walls save a few of a handful of tests a ray; where
            // the spheres are many, the hierarchy finds them, walls or not
            return Walls::default();
        }
        let eye_f32 = eye;
        let eye = eye.as_dvec3();
        let is_wall = |region: &Region, object: u32| {
            opaque(object)
                && region.holds_strictly(eye)
                && lights.iter().all(|light| light.held_by(&|center, reach| region.holds(center, reach), object))
        };
        let s = spheres;
        let (mut regions, mut others, mut wall_spheres) = (Vec::new(), Vec::new(), Vec::new());
        for (j, sphere) in s.list.iter().enumerate() {
            let region = Region::ball(sphere.center, sphere.radius);
            let wall = is_wall(&region, sphere.object);
            if wall {
                regions.push(region);
                wall_spheres.push((j as u32, AnchoredSphere::new(sphere.center, sphere.radius, eye_f32)));
            } else {
                others.push(j);
            }
        }
        let (mut kept_planes, mut wall_planes) = (Vec::new(), Vec::new());
        for plane in planes {
            // Facing the camera's side
            let (normal, offset) = (plane.normal.as_dvec3(), plane.offset as f64);
            let side = if normal.dot(eye) > offset { 1.0 } else { -1.0 };
            let region = Region::HalfSpace { normal: normal * side, offset: offset * side };
            if is_wall(&region, plane.object) {
                regions.push(region);
                let (inward, offset) = (plane.normal * side as f32, plane.offset * side as f32);
                wall_planes.push(WallPlane { plane: *plane, inward, offset });
            } else {
                kept_planes.push(*plane);
            }
        }
        if regions.is_empty() {
            return Walls::default();
        }
        let centers: Vec<Vec3> = others.iter().map(|&j| s.center(j)).collect();
        let radii: Vec<f32> = others.iter().map(|&j| s.radius(j)).collect();
        let ids = others.iter().map(|&j| j as u32).collect();
        Walls {
            regions,
            spheres: SphereLanes::new(&centers, &radii, ids),
            planes: kept_planes,
            wall_spheres,
            wall_planes,
        }
    }

    /// Whether a path starting at `origin` is inside every wall (and there are walls).
    #[inline]
    pub(crate) fn hold(&self, origin: Vec3) -> bool {
        !self.regions.is_empty() && self.regions.iter().all(|region| region.holds_strictly_f32(origin))
    }

    /// Whether every path starting in the box [min, max] is inside every
    /// wall: walls bound convex regions, so the box's corners decide.
    pub(crate) fn hold_box(&self, min: Vec3, max: Vec3) -> bool {
        let mut corners = (0..8).map(|i| {
            let pick = |bit: u32, low: f32, high: f32| if i & bit == 0 { low } else { high };
            DVec3::new(pick(1, min.x, max.x) as f64, pick(2, min.y, max.y) as f64, pick(4, min.z, max.z) as f64)
        });
        !self.regions.is_empty()
            && min.cmple(max).all()
            && corners.all(|p| self.regions.iter().all(|region| region.holds_strictly(p)))
    }

    /// `hold` for eight origins: in f32 lanes, and lane by lane where a
    /// point is too close to a wall to call there.
    #[inline(always)]
    pub(crate) fn hold_lanes(&self, origins: V8) -> M8 {
        if self.regions.is_empty() {
            return M8::NONE;
        }
        let (mut out, mut unsure) = (M8::NONE, M8::NONE);
        for region in &self.regions {
            match *region {
                Region::Ball { center_f32, surely_in2, surely_out2, .. } => {
                    let distance2 = (origins - V8::splat(center_f32)).length_squared();
                    let surely_out = distance2.gt(F8::splat(surely_out2));
                    out = out.or(surely_out);
                    unsure = unsure.or(!distance2.lt(F8::splat(surely_in2)).or(surely_out));
                }
                Region::HalfSpace { .. } => unsure = M8::ALL,
            }
        }
        let mut held = !out;
        for lane in unsure.and_not(out).lanes() {
            held.set(lane, self.hold(origins.lane(lane)));
        }
        held
    }
}

/// What can block the shadow rays of one path.
#[derive(Clone, Copy)]
pub struct Occluders<'w> {
    spheres: SphereReach<'w>,
    planes: &'w [PlaneShape],
    /// The world's shapes, for its triangles.
    shapes: &'w Shapes,
    /// Per triangle, the light triangle whose plane holds it (`u32::MAX` if none).
    light_plane: &'w [u32],
}

impl<'w> Occluders<'w> {
    /// For a path that is `held` inside every wall (`Walls::hold` of where
    /// it started): without the walls.
    #[inline]
    pub fn for_path(walls: &'w Walls, shapes: &'w Shapes, light_plane: &'w [u32], held: bool) -> Self {
        let (spheres, planes) = match held {
            true => (SphereReach::Groups(&walls.spheres), &walls.planes[..]),
            false => (SphereReach::All(&shapes.spheres), &shapes.planes[..]),
        };
        Occluders { spheres, planes, shapes, light_plane }
    }

    /// Whether anything lies between the shading point and the light sample.
    #[inline]
    pub fn blocks(&self, sample: &LightSample) -> bool {
        self.blocks_shadow(&Shadow::toward(sample, false))
    }

    /// Whether anything but what `shadow` ends on lies on it (its `held`
    /// is this path's, which chose the occluders).
    #[inline]
    pub fn blocks_shadow(&self, shadow: &Shadow) -> bool {
        let (ray, t_max) = (&shadow.ray, shadow.t_max);
        let light_plane = shadow.on_triangle.map(|t| self.light_plane[t as usize]);
        self.spheres.any_hit_except(ray, t_max, shadow.on_sphere)
            || self.planes.iter().any(|p| plane_t(ray, p.normal, p.offset, t_max).is_some())
            || (self.shapes).any_triangle(ray, t_max, |i| light_plane == Some(self.light_plane[i as usize]))
    }
}

/// A shadow ray to trace: the segment, whether both its ends lie inside
/// every wall (which it then cannot cross), and what it ends on, which it
/// meets only at its end: the sphere or the triangle (and so the plane of
/// triangles) a light sample lies on.
#[derive(Clone, Copy, Debug)]
pub struct Shadow {
    pub ray: Ray,
    pub t_max: f32,
    pub held: bool,
    pub on_sphere: Option<u32>,
    pub on_triangle: Option<u32>,
}

impl Shadow {
    /// Between two points of paths (or one and the camera): nothing to skip.
    #[inline]
    pub fn segment(ray: Ray, t_max: f32, held: bool) -> Self {
        Shadow { ray, t_max, held, on_sphere: None, on_triangle: None }
    }

    /// Toward a light sample, from a path `held` inside every wall or not.
    #[inline]
    pub fn toward(sample: &LightSample, held: bool) -> Self {
        let (on_sphere, on_triangle) = (sample.on_sphere, sample.on_triangle);
        Shadow { ray: sample.shadow, t_max: sample.shadow_t_max, held, on_sphere, on_triangle }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{intersect_triangle, sphere_t, Ray};
    use crate::render::world::camera::CameraModel;
    use crate::render::world::lanes::LANES;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;
    use crate::render::world::World;
    use crate::scene::{Light, LightKind, Scene};

    fn preset(name: &str) -> Scene {
        crate::scene::presets::preset(name).and_then(Result::ok).expect("preset").into_scene()
    }

    fn world(scene: &Scene) -> World {
        let valid = crate::scene::ValidScene::new(scene.clone()).expect("valid");
        World::for_view(&valid, &CameraModel::new(&scene.camera, 64, 48), 64, 48).0
    }

    fn point_light(position: Vec3) -> Light {
        Light {
            name: "extra".into(),
            kind: LightKind::Point { position },
            color: Vec3::ONE,
            intensity: 1.0,
            attenuation: Default::default(),
            enabled: true,
        }
    }

    #[test]
    fn walls_of_smallpt_and_the_cornell_box() {
        let w = world(&preset("smallpt"));
        assert_eq!((w.walls.regions.len(), w.walls.spheres.len(), w.walls.planes.len()), (6, 3, 0));
        let w = world(&preset("cornell"));
        assert_eq!((w.walls.regions.len(), w.walls.spheres.len(), w.walls.planes.len()), (5, 2, 0));
        assert_eq!(w.light_plane, [0, 0], "the panel's two halves share a plane");
    }

    /// A wall must hold every light: a point light above smallpt's ceiling
    /// leaves five walls, a directional light none.
    #[test]
    fn a_light_outside_a_wall_keeps_it_tested() {
        let mut scene = preset("smallpt");
        scene.lights.push(point_light(Vec3::new(50.0, 200.0, 80.0)));
        let w = world(&scene);
        assert_eq!((w.walls.regions.len(), w.walls.spheres.len()), (5, 4));
        let sun = LightKind::Directional { direction: -Vec3::Y };
        scene.lights.push(Light { name: "sun".into(), kind: sun, ..point_light(Vec3::ZERO) });
        assert!(world(&scene).walls.regions.is_empty());
        let mut scene = preset("cornell");
        scene.lights.push(point_light(Vec3::new(0.0, 1.0, -3.0)));
        let w = world(&scene);
        assert_eq!((w.walls.regions.len(), w.walls.planes.len()), (4, 1), "the back wall has a light behind it");
    }

    /// A path that starts outside a wall (a camera above smallpt's
    /// ceiling) tests everything.
    #[test]
    fn paths_from_outside_test_every_sphere() {
        let w = world(&preset("smallpt"));
        assert_eq!(w.occluders(w.holds(Vec3::new(50.0, 52.0, 150.0))).spheres.len(), 3);
        assert_eq!(w.occluders(w.holds(Vec3::new(50.0, 82.0, 150.0))).spheres.len(), 9);
    }

    /// The f32 shortcut answers as f64 does, on points within a few ulps of
    /// where paths may start inside smallpt's radius-1e5 walls and far from it.
    #[test]
    fn the_f32_inside_test_agrees_with_f64() {
        let w = world(&preset("smallpt"));
        let mut s = Sampler::new(1, 2, 3);
        let (mut near_in, mut near_out) = (0, 0);
        for region in &w.walls.regions {
            let Region::Ball { center_f32, start_radius, .. } = *region else { continue };
            for _ in 0..20_000 {
                // 1e-5 to 1e4 units from where paths may start, either side
                let offset = (10.0f64).powf(-5.0 + 9.0 * s.next_f32() as f64) * (2.0 * s.next_f32() as f64 - 1.0);
                let p = (center_f32.as_dvec3() + uniform_sphere(s.next_2d()).as_dvec3() * (start_radius + offset))
                    .as_vec3();
                let exact = region.holds_strictly(p.as_dvec3());
                assert_eq!(region.holds_strictly_f32(p), exact, "{p} at {offset} from the surface");
                if offset.abs() < 0.1 {
                    (near_in, near_out) = (near_in + exact as u32, near_out + !exact as u32);
                }
            }
        }
        assert!(near_in > 1000 && near_out > 1000, "{near_in} in, {near_out} out near the surface");
    }

    /// A box inside every wall holds every point in it; one that crosses a
    /// wall, or an empty one, holds nothing.
    #[test]
    fn a_box_of_origins_is_held_by_its_corners() {
        let w = world(&preset("smallpt"));
        let mut s = Sampler::new(4, 5, 6);
        let (low, high) = (Vec3::new(40.0, 40.0, 150.0), Vec3::new(60.0, 60.0, 169.9));
        assert!(w.walls.hold_box(low, high));
        for _ in 0..1000 {
            let p = low + (high - low) * Vec3::new(s.next_f32(), s.next_f32(), s.next_f32());
            assert!(w.walls.hold(p), "{p}");
        }
        // Past the front wall (z = 170), past the ceiling, and inside out
        assert!(!w.walls.hold_box(low, Vec3::new(60.0, 60.0, 170.5)));
        assert!(!w.walls.hold_box(low, Vec3::new(60.0, 82.0, 160.0)));
        assert!(!w.walls.hold_box(high, low));
        assert!(!Walls::default().hold_box(low, low), "no walls, nothing held");
    }

    /// Eight origins at a time are held as one at a time: points in and
    /// around smallpt's room, half of them 1e-5 to 3 units from a wall where
    /// the f32 test cannot call it, and a NaN.
    #[test]
    fn walls_hold_lanes_as_they_hold_points() {
        assert!(crate::render::world::lanes::supported(), "the lanes need AVX2");
        let w = world(&preset("smallpt"));
        let mut s = Sampler::new(4, 5, 6);
        let (low, high) = (Vec3::new(-1.0, -1.0, -1.0), Vec3::new(101.0, 83.0, 172.0));
        // The walls' planes: x = 1, 99; y = 0, 81.6; z = 0, 170
        let planes = [(0, 1.0), (0, 99.0), (1, 0.0), (1, 81.6), (2, 0.0), (2, 170.0)];
        let mut held = 0;
        for _ in 0..5_000 {
            let points: [Vec3; LANES] = std::array::from_fn(|_| {
                let mut p = low + (high - low) * Vec3::new(s.next_f32(), s.next_f32(), s.next_f32());
                if s.next_f32() < 0.5 {
                    let (axis, at) = planes[s.next_u64() as usize % planes.len()];
                    p[axis] = at + (10.0f32).powf(-5.0 + 5.5 * s.next_f32()) * (2.0 * s.next_f32() - 1.0);
                }
                p
            });
            let mut origins = V8::from_fn(|i| points[i]);
            if s.next_f32() < 0.1 {
                origins.x.set_lane(7, f32::NAN);
            }
            let lanes = w.walls.hold_lanes(origins);
            for lane in 0..LANES {
                assert_eq!(lanes.test(lane), w.walls.hold(origins.lane(lane)), "{}", origins.lane(lane));
                held += lanes.test(lane) as u32;
            }
        }
        assert!(held > 2_000, "only {held} points held");
        assert_eq!(Walls::default().hold_lanes(V8::splat(Vec3::ZERO)), M8::NONE, "no walls, nothing held");
    }

    /// Whether `p` lies outside a wall's region, beyond the rounding of
    /// points on it (`on_a_wall`).
    fn outside_a_wall(walls: &Walls, p: DVec3) -> bool {
        walls.regions.iter().any(|region| match *region {
            Region::Ball { center, radius, .. } => (p - center).length() - radius > 1e-7 * radius + 1e-4,
            Region::HalfSpace { normal, offset } => offset - normal.dot(p) > 1e-6 * (1.0 + offset.abs()),
        })
    }

    /// Whether `p` lies within rounding of a wall's surface.
    fn on_a_wall(walls: &Walls, p: DVec3) -> bool {
        walls.regions.iter().any(|region| match *region {
            Region::Ball { center, radius, .. } => ((p - center).length() - radius).abs() <= 1e-7 * radius + 1e-4,
            Region::HalfSpace { normal, offset } => (normal.dot(p) - offset).abs() <= 1e-6 * (1.0 + offset.abs()),
        })
    }

    /// Against testing everything, on random paths through every preset,
    /// through smallpt and the Cornell box with a point light outside one
    /// wall, and through the Cornell box with a triangle under its panel. Skipping may lose only blockers that rounding put at the
    /// very end of a segment: a light sample on a wall's surface (smallpt's
    /// light is cut at the ceiling), or one a hair behind its own plane.
    #[test]
    fn skipping_agrees_with_testing_everything() {
        let mut scenes: Vec<(String, Scene)> =
            ["smallpt", "cornell", "caustics", "lights", "thesis"].map(|n| (n.to_string(), preset(n))).into();
        for (name, outside) in [("smallpt", Vec3::new(50.0, 100.0, 80.0)), ("cornell", Vec3::new(0.0, 1.0, -1.5))] {
            let mut scene = preset(name);
            scene.lights.push(point_light(outside));
            scenes.push((format!("{name} with a light outside"), scene));
        }
        // A white triangle under the panel: a blocker that no skip may lose
        let mut scene = preset("cornell");
        scene.objects.push(crate::scene::Object {
            name: "shade".into(),
            shape: crate::scene::Shape::Triangle {
                a: Vec3::new(-0.5, 1.6, -0.5),
                b: Vec3::new(0.5, 1.6, -0.5),
                c: Vec3::new(0.0, 1.6, 0.5),
            },
            material: "white".into(),
        });
        scenes.push(("cornell with a shade".into(), scene));
        for (name, scene) in &scenes {
            let w = world(scene);
            let camera = CameraModel::new(&scene.camera, 64, 48);
            let mut s = Sampler::new(0, 0, 5);
            let (mut samples, mut blocked, mut skipping_paths, mut leaks) = (0u32, 0u32, 0u32, 0u32);
            for _ in 0..4000 {
                let mut ray = camera.pixel_ray(64.0 * s.next_f32(), 48.0 * s.next_f32());
                let occluders = w.occluders(w.holds(ray.origin));
                let skips = occluders.spheres.len() + occluders.planes.len()
                    < w.shapes.spheres.lanes.len() + w.shapes.planes.len();
                skipping_paths += skips as u32;
                for _ in 0..4 {
                    let Some(hit) = w.intersect(&ray, f32::INFINITY) else { break };
                    if skips && outside_a_wall(&w.walls, hit.surface.point.as_dvec3()) {
                        // Where two walls meet within rounding, the nearer hit may lie
                        // outside the other: the path has left the box, walls and all
                        leaks += 1;
                        break;
                    }
                    for light in &w.lights {
                        let Some(sample) = light.sample(&hit.surface, s.next_2d()) else { continue };
                        let (shadow, t_max) = (&sample.shadow, sample.shadow_t_max);
                        let everything = w.occluded(shadow, t_max);
                        let skipping = occluders.blocks(&sample);
                        samples += 1;
                        blocked += everything as u32;
                        if everything == skipping {
                            continue;
                        }
                        assert!(everything, "{name}: skipping found a blocker testing everything did not");
                        let own_plane = sample.on_triangle.is_some_and(|t| {
                            w.shapes.triangles.list.iter().zip(&w.light_plane).any(|((triangle, _), plane)| {
                                *plane == w.light_plane[t as usize]
                                    && intersect_triangle(shadow, triangle, t_max).is_some()
                            })
                        });
                        let own_sphere = sample.on_sphere.is_some_and(|i| {
                            sphere_t(
                                shadow,
                                w.shapes.spheres.center(i as usize),
                                w.shapes.spheres.radius(i as usize),
                                t_max,
                            )
                            .is_some()
                        });
                        let target = shadow.origin.as_dvec3() + shadow.direction.as_dvec3() * t_max as f64;
                        assert!(
                            own_plane || own_sphere || on_a_wall(&w.walls, target),
                            "{name}: a blocker skipped in the open, target {target}"
                        );
                    }
                    let mut direction = uniform_sphere(s.next_2d());
                    if direction.dot(hit.surface.normal) * (-ray.direction).dot(hit.surface.normal) < 0.0 {
                        direction = -direction;
                    }
                    ray = Ray::new(hit.surface.spawn_ray(direction).origin, direction);
                }
            }
            assert!(samples > 4000 && blocked > samples / 50, "{name}: {blocked} of {samples} blocked");
            assert!(leaks <= 4, "{name}: {leaks} of 4000 paths left the walls");
            if name == "smallpt" || name.starts_with("cornell") {
                assert!(skipping_paths > 3000, "{name}: only {skipping_paths} paths skip walls");
            }
        }
    }
}
