//! The f32 geometry on its hard cases: smallpt's walls of radius 1e5, tiny
//! and distant spheres, tangent and long rays, respawned rays at every scale,
//! a watertight mesh, degenerate and nested shapes, signed zeros.

mod common;

use common::*;
use gi_studio::analysis::metrics::{rel_mse, RelMseOptions};
use gi_studio::geometry::{intersect_plane, intersect_sphere, intersect_triangle, Ray, Triangle};
use gi_studio::render::integrators::{whitted, Counters};
use gi_studio::render::world::camera::CameraModel;
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::cosine_hemisphere;
use gi_studio::render::world::World;
use gi_studio::render::Algorithm;
use gi_studio::scene::{presets, LightKind, MaterialModel, Scene, Shape};
use glam::{DVec3, Vec3};

/// smallpt's box: camera rays start inside the front wall's sphere, and
/// no bounce off a wall finds the same wall again right where it started.
#[test]
fn smallpt_walls_show_no_acne() {
    let scene = presets::preset("smallpt").unwrap().unwrap();
    let world = World::new(&valid(scene.clone()));
    let camera = CameraModel::new(&scene.camera, 64, 48);
    let front = Vec3::new(50.0, 40.8, -99830.0);
    let mut s = Sampler::new(0, 0, 1);
    for y in 0..48 {
        for x in 0..64 {
            let mut ray = camera.pixel_ray(x as f32 + 0.5, y as f32 + 0.5);
            assert!((ray.origin - front).length() < 1.0e5, "the near clip puts origins inside the front wall's sphere");
            for _bounce in 0..6 {
                let Some(hit) = world.intersect(&ray, f32::INFINITY) else { break };
                let n =
                    if hit.surface.normal.dot(ray.direction) < 0.0 { hit.surface.normal } else { -hit.surface.normal };
                let d = gi_studio::geometry::Frame::from_z(n).to_world(cosine_hemisphere(s.next_2d()));
                let next = hit.surface.spawn_ray(d);
                if let Some(again) = world.intersect(&next, f32::INFINITY) {
                    assert!(
                        !(again.object == hit.object && again.surface.t < 0.05),
                        "acne: object {} re-hit at t = {}",
                        hit.object,
                        again.surface.t
                    );
                }
                ray = next;
            }
        }
    }
}

/// A radius-0.1 sphere hit by a ray from (−1e7, 0.095, 0) along +x.
#[test]
fn a_tiny_sphere_hit_from_afar_has_the_right_normal() {
    let hit =
        intersect_sphere(&Ray::new(Vec3::new(-1.0e7, 0.095, 0.0), Vec3::X), Vec3::ZERO, 0.1, f32::INFINITY).unwrap();
    let expected = DVec3::new(-(0.01f64 - 0.095f64.powi(2)).sqrt(), 0.095, 0.0);
    assert!((hit.point.as_dvec3() - expected).length() < 1e-6);
    assert!((hit.normal.as_dvec3() - expected / 0.1).length() < 1e-5);
}

/// A sphere 8e5 units away seen from z = 1000: shading matches the f64
/// oracle pixel by pixel (rings would be errors of the hit normal).
#[test]
fn a_distant_sphere_shades_without_rings() {
    let center = Vec3::new(0.0, 0.0, -8.0e5);
    let radius = 1.0e5;
    let sun = Vec3::new(-0.3, -0.5, -1.0).normalize();
    let mut scene = scene(
        camera(Vec3::new(0.0, 0.0, 1000.0), center),
        vec![material("clay", lambert(0.8))],
        vec![object("far ball", Shape::Sphere { center, radius }, "clay")],
        vec![light("sun", LightKind::Directional { direction: sun }, 1.0)],
    );
    scene.camera.fov_y_degrees = 15.0;
    let world = World::new(&valid(scene.clone()));
    let camera = CameraModel::new(&scene.camera, 48, 48);
    let mut counters = Counters::default();
    for y in 0..48 {
        for x in 0..48 {
            let ray = camera.pixel_ray(x as f32 + 0.5, y as f32 + 0.5);
            let got = whitted::radiance(&world, &ray, 1, &mut Sampler::new(0, 0, 0), &mut counters).x as f64;
            let (o, d, c) = (ray.origin.as_dvec3(), ray.direction.as_dvec3(), center.as_dvec3());
            let f = o - c;
            let b = f.dot(d);
            let disc = (radius as f64).powi(2) - (f - b * d).length_squared();
            let expected = if disc < 0.0 {
                0.0
            } else {
                let n = (o + d * (-b - disc.sqrt()) - c).normalize();
                0.8 / std::f64::consts::PI * n.dot(-sun.as_dvec3()).max(0.0)
            };
            // Far from the silhouette, the f32 shading agrees closely
            if disc > 0.05 * (radius as f64).powi(2) {
                assert!((got - expected).abs() < 2e-3, "pixel ({x},{y}): {got} vs {expected}");
            }
        }
    }
}

/// Tangent rays (discriminant ≈ 0): never the square root of a negative;
/// a ray passing inside the silhouette by more than rounding hits, one
/// passing outside it misses (an intersector that gives up near tangency
/// fails here), and every hit lies on the sphere.
#[test]
fn tangent_rays_never_take_a_negative_root() {
    let mut hits = 0;
    for i in 0..4000 {
        let y = 1.0 - 2.0e-3 + i as f32 * 1.0e-6;
        for origin_x in [-10.0f32, -1.0e4] {
            let hit = intersect_sphere(&Ray::new(Vec3::new(origin_x, y, 0.0), Vec3::X), Vec3::ZERO, 1.0, f32::INFINITY);
            // 1 − y² against the f32 error of the solve at this distance
            let margin = 1e-4 * (origin_x.abs() / 10.0).max(1.0).log10().max(1.0);
            if y < 1.0 - margin {
                assert!(hit.is_some(), "y = {y} from x = {origin_x}: inside the silhouette, missed");
            } else if y > 1.0 + margin {
                assert!(hit.is_none(), "y = {y} from x = {origin_x}: outside the silhouette, hit");
            }
            if let Some(hit) = hit {
                hits += 1;
                assert!(hit.t.is_finite() && hit.point.is_finite() && hit.normal.is_finite());
                assert!((hit.normal.length() - 1.0).abs() < 1e-5);
                assert!((hit.point.length() - 1.0).abs() < 1e-3, "a hit off the sphere at {}", hit.point);
            }
        }
    }
    assert!(hits > 3000, "about half the rays pass inside: {hits} of 8000 hit");
}

/// Re-intersection sweep: hits at scales 1e-8 … 1e8; rays leaving a
/// surface never re-hit it, rays entering a sphere reach its far side, and
/// shadow rays toward points outside are never blocked by it.
#[test]
fn respawned_rays_never_hit_their_own_surface() {
    let mut s = Sampler::new(0, 0, 2024);
    let mut checked = 0;
    for exponent in -8..=8 {
        let scale = 10f32.powi(exponent);
        for _ in 0..200 {
            let center = (Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 20.0 - 10.0) * scale;
            let radius = scale * (0.5 + 1.5 * s.next_f32());
            let origin = center + random_direction(&mut s) * radius * (2.0 + 18.0 * s.next_f32());
            let target = center + random_direction(&mut s) * radius * 0.9 * s.next_f32();
            let ray = Ray::new(origin, (target - origin).normalize());
            let hit = intersect_sphere(&ray, center, radius, f32::INFINITY).expect("aimed inside");
            for _ in 0..8 {
                let mut d = random_direction(&mut s);
                if d.dot(hit.normal) < 0.0 {
                    d = -d;
                }
                assert!(
                    intersect_sphere(&hit.spawn_ray(d), center, radius, f32::INFINITY).is_none(),
                    "scale {scale}: self-hit leaving"
                );
                let outside = hit.point + d * radius * (0.01 + 3.0 * s.next_f32());
                let (shadow, t_max) = hit.spawn_ray_to(outside, 0.0);
                assert!(intersect_sphere(&shadow, center, radius, t_max).is_none(), "scale {scale}: shadow self-hit");
                if -d.dot(hit.normal) > 0.1 {
                    let inner = intersect_sphere(&hit.spawn_ray(-d), center, radius, f32::INFINITY)
                        .expect("entering ray must reach the far side");
                    assert!(inner.t > 0.1 * radius, "scale {scale}: re-hit at t = {}", inner.t);
                }
                checked += 1;
            }
            let normal = random_direction(&mut s);
            let offset = normal.dot(center);
            let toward = if normal.dot(origin) > offset { -1.0 } else { 1.0 };
            let to_plane = Ray::new(origin, (normal * toward + random_direction(&mut s) * 0.5).normalize());
            if let Some(hit) = intersect_plane(&to_plane, normal, offset, f32::INFINITY) {
                for side in [1.0, -1.0] {
                    let d = (hit.normal * side + random_direction(&mut s) * 0.7).normalize();
                    if d.dot(hit.normal) * side > 0.0 {
                        assert!(
                            intersect_plane(&hit.spawn_ray(d), normal, offset, f32::INFINITY).is_none(),
                            "scale {scale}: plane self-hit"
                        );
                    }
                }
            }
            let [a, b, c] = [0, 1, 2].map(|_| center + random_direction(&mut s) * radius);
            let triangle = Triangle::new(a, b, c);
            let to_triangle = Ray::new(origin, ((a + b + c) / 3.0 - origin).normalize());
            if let Some(hit) = intersect_triangle(&to_triangle, &triangle, f32::INFINITY) {
                for side in [1.0, -1.0] {
                    let d = (hit.normal * side + random_direction(&mut s) * 0.7).normalize();
                    if d.dot(hit.normal) * side > 0.0 {
                        assert!(
                            intersect_triangle(&hit.spawn_ray(d), &triangle, f32::INFINITY).is_none(),
                            "scale {scale}: triangle self-hit"
                        );
                    }
                }
            }
        }
    }
    assert_eq!(checked, 17 * 200 * 8);
}

/// An icosphere of radius 1: closed, every edge shared by two triangles.
fn icosphere(subdivisions: u32) -> Vec<[Vec3; 3]> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let v = [
        Vec3::new(-1.0, t, 0.0),
        Vec3::new(1.0, t, 0.0),
        Vec3::new(-1.0, -t, 0.0),
        Vec3::new(1.0, -t, 0.0),
        Vec3::new(0.0, -1.0, t),
        Vec3::new(0.0, 1.0, t),
        Vec3::new(0.0, -1.0, -t),
        Vec3::new(0.0, 1.0, -t),
        Vec3::new(t, 0.0, -1.0),
        Vec3::new(t, 0.0, 1.0),
        Vec3::new(-t, 0.0, -1.0),
        Vec3::new(-t, 0.0, 1.0),
    ]
    .map(Vec3::normalize);
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles: Vec<[Vec3; 3]> = faces.iter().map(|f| [v[f[0]], v[f[1]], v[f[2]]]).collect();
    for _ in 0..subdivisions {
        triangles = triangles
            .iter()
            .flat_map(|[a, b, c]| {
                let (ab, bc, ca) = ((*a + *b).normalize(), (*b + *c).normalize(), (*c + *a).normalize());
                [[*a, ab, ca], [*b, bc, ab], [*c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    triangles
}

/// A closed triangulated sphere: rays from inside, aimed exactly at
/// vertices, edge midpoints and at random, always hit (watertight).
#[test]
fn a_closed_mesh_is_watertight() {
    let mesh: Vec<Triangle> = icosphere(2).into_iter().map(|[a, b, c]| Triangle::new(a, b, c)).collect();
    let mut targets: Vec<Vec3> =
        mesh.iter().flat_map(|t| [t.vertices[0], (t.vertices[0] + t.vertices[1]) * 0.5]).collect();
    let mut s = Sampler::new(6, 0, 6);
    targets.extend((0..20_000).map(|_| random_direction(&mut s)));
    for origin in [Vec3::ZERO, Vec3::new(0.1, -0.2, 0.05), Vec3::new(0.0, 0.0, 0.3)] {
        for target in &targets {
            let ray = Ray::new(origin, (*target - origin).normalize());
            assert!(
                mesh.iter().any(|t| intersect_triangle(&ray, t, f32::INFINITY).is_some()),
                "ray from {origin} toward {target} escaped"
            );
        }
    }
}

/// Degenerate triangles (zero area, collinear, far from the origin): never
/// hit, never NaN, and a scene holding them renders finite.
#[test]
fn degenerate_triangles_are_never_hit() {
    let far = Vec3::splat(3.0e7);
    let degenerate = [
        Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X),
        Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE),
        Triangle::new(far, far + Vec3::X, far + 2.0 * Vec3::X),
        Triangle::new(far, far + Vec3::splat(1e-3), far + Vec3::splat(2e-3)),
    ];
    let mut s = Sampler::new(7, 0, 7);
    for t in &degenerate {
        assert!(t.is_degenerate() && t.normal.is_finite());
        for _ in 0..2000 {
            let origin = t.vertices[0] + random_direction(&mut s) * 2.0;
            let ray = Ray::new(origin, (t.vertices[1] - origin).normalize());
            assert!(intersect_triangle(&ray, t, f32::INFINITY).is_none());
        }
    }
    let mut scene = floor_scene(0.5, vec![light("sun", LightKind::Directional { direction: -Vec3::Y }, 1.0)]);
    scene.objects.push(object("flat", Shape::Triangle { a: Vec3::ZERO, b: Vec3::X, c: 2.0 * Vec3::X }, "floor"));
    let (_, non_finite) = render(&scene, settings(Algorithm::Path, 16, 12, 2));
    assert_eq!(non_finite, 0);
}

/// Nested surfaces 4e-5 apart: after the outer sphere the inner is found.
#[test]
fn nested_spheres_are_found_in_order() {
    let (inner, outer) = (1.0f32, 1.0f32 + 4.0e-5);
    let mut s = Sampler::new(8, 0, 8);
    for _ in 0..2000 {
        let origin = random_direction(&mut s) * 5.0;
        let target = random_direction(&mut s) * 0.5;
        let ray = Ray::new(origin, (target - origin).normalize());
        let hit = intersect_sphere(&ray, Vec3::ZERO, outer, f32::INFINITY).unwrap();
        let through = hit.spawn_ray(ray.direction);
        let next = intersect_sphere(&through, Vec3::ZERO, inner, f32::INFINITY).expect("the inner sphere is found");
        let depth = (next.point.length() - inner).abs();
        assert!(depth < 1e-6 && next.t < 1.0e-3 / ray.direction.dot(-hit.normal).max(0.05), "t = {}", next.t);
    }
}

/// A sphere on a floor lit by a point light and the sun, every length
/// multiplied by `scale` (the point light's intensity by scale² so the
/// irradiance stays the same).
fn scaled_scene(scale: f32) -> Scene {
    let mut scene = scene(
        camera(Vec3::new(0.0, 2.0, 5.0) * scale, Vec3::new(0.0, 0.5, 0.0) * scale),
        vec![
            material("floor", lambert(0.6)),
            material(
                "plastic",
                MaterialModel::Phong {
                    ka: Vec3::splat(0.1),
                    kd: Vec3::splat(0.5),
                    ks: Vec3::splat(0.3),
                    shininess: 30.0,
                },
            ),
        ],
        vec![
            object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
            object("ball", Shape::Sphere { center: Vec3::new(0.0, 0.5, 0.0) * scale, radius: 0.5 * scale }, "plastic"),
        ],
        vec![
            light("bulb", LightKind::Point { position: Vec3::new(2.0, 3.0, 1.0) * scale }, 20.0 * scale * scale),
            light("sun", LightKind::Directional { direction: Vec3::new(-0.3, -1.0, -0.4) }, 0.5),
        ],
    );
    scene.ambient = Vec3::splat(0.05);
    scene
}

/// The same scene scaled by 1e-3 … 1e7 renders the same image.
#[test]
fn a_scene_renders_the_same_at_every_scale() {
    let base = render(&scaled_scene(1.0), settings(Algorithm::Whitted, 48, 36, 2)).0;
    for scale in [1e-3f32, 1e-1, 10.0, 1e3, 1e5, 1e7] {
        let image = render(&scaled_scene(scale), settings(Algorithm::Whitted, 48, 36, 2)).0;
        let error = rel_mse(&image, &base, RelMseOptions::default()).unwrap();
        assert!(error < 1e-3, "scale {scale}: relMSE {error}");
    }
}

/// Long rays (t ≈ 1e6) land on the surface and leave it cleanly.
#[test]
fn long_rays_land_and_leave_cleanly() {
    let mut s = Sampler::new(10, 0, 10);
    for _ in 0..1000 {
        let slope = 1.0e-6 * (1.0 + s.next_f32());
        let d = Vec3::new(1.0, -slope, s.next_f32() * 0.1).normalize();
        let hit = intersect_plane(&Ray::new(Vec3::new(0.0, 1.0, 0.0), d), Vec3::Y, 0.0, f32::INFINITY)
            .expect("reaches the floor");
        assert!(hit.t > 4.0e5 && hit.t.is_finite());
        assert!(hit.point.y.abs() <= hit.error);
        assert!(intersect_plane(&hit.spawn_ray(Vec3::new(0.3, 1.0, 0.0).normalize()), Vec3::Y, 0.0, f32::INFINITY)
            .is_none());
    }
    let far =
        intersect_sphere(&Ray::new(Vec3::ZERO, Vec3::Z), Vec3::new(0.0, 0.0, 1.0e6), 10.0, f32::INFINITY).unwrap();
    assert!((far.t - (1.0e6 - 10.0)).abs() < 0.1);
}

/// Axis-aligned directions with ±0.0 components, origins exactly on a
/// plane, rays parallel to a plane.
#[test]
fn signed_zeros_and_rays_in_planes_behave() {
    let triangle = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
    for d in
        [Vec3::new(0.0, 0.0, -1.0), Vec3::new(-0.0, 0.0, -1.0), Vec3::new(0.0, -0.0, -1.0), Vec3::new(-0.0, -0.0, -1.0)]
    {
        let hit = intersect_triangle(&Ray::new(Vec3::new(0.0, 0.0, 1.0), d), &triangle, f32::INFINITY).expect("hit");
        assert_eq!(hit.t, 1.0);
        let sphere = intersect_sphere(&Ray::new(Vec3::new(0.0, 0.0, 3.0), d), Vec3::ZERO, 1.0, f32::INFINITY).unwrap();
        assert_eq!(sphere.t, 2.0);
    }
    // On the plane: moving away or along it never hits; moving into it would
    // need t = 0, which is not in (0, ∞)
    let on = Ray::new(Vec3::new(3.0, 0.0, -2.0), Vec3::Y);
    assert!(intersect_plane(&on, Vec3::Y, 0.0, f32::INFINITY).is_none());
    assert!(intersect_plane(&Ray::new(Vec3::new(3.0, 0.0, -2.0), Vec3::X), Vec3::Y, 0.0, f32::INFINITY).is_none());
    assert!(intersect_plane(&Ray::new(Vec3::new(3.0, 0.0, -2.0), -Vec3::Y), Vec3::Y, 0.0, f32::INFINITY).is_none());
    assert!(intersect_plane(
        &Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, -0.0, 0.0)),
        Vec3::Y,
        0.0,
        f32::INFINITY
    )
    .is_none());
}
