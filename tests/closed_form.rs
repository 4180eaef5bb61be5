//! Renders checked against radiance known in closed form.

mod common;

use std::f32::consts::PI;
use std::sync::Arc;

use common::detectors;
use common::*;
use gi_studio::geometry::Ray;
use gi_studio::render::integrators::{path, whitted, Counters};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::World;
use gi_studio::render::{render_blocking, Algorithm, RenderJob, RenderSettings};
use gi_studio::scene::{LightKind, MaterialModel, Shape};
use glam::Vec3;

fn trace(algorithm: Algorithm, world: &World, ray: &Ray, samples: u32) -> Vec3 {
    let mut counters = Counters::default();
    let mut sum = Vec3::ZERO;
    for s in 0..samples {
        let mut sampler = Sampler::new(1, s as u64, 7);
        sum += match algorithm {
            Algorithm::Whitted => whitted::radiance(world, ray, 5, &mut sampler, &mut counters),
            _ => path::radiance(world, ray, 32, &mut sampler, &mut counters),
        };
    }
    sum / samples as f32
}

fn render(scene: gi_studio::scene::Scene, algorithm: Algorithm, spp: u32) -> gi_studio::render::LinearImage {
    let settings = RenderSettings {
        width: scene.settings.width,
        height: scene.settings.height,
        samples_per_pixel: Some(spp),
        ..RenderSettings::for_algorithm(algorithm)
    };
    render_blocking(&RenderJob::new(Arc::new(valid(scene)), settings)).expect("renders").0
}

#[test]
fn lambert_plane_under_a_directional_light() {
    let direction = Vec3::new(0.3, -1.0, -0.5).normalize();
    let scene = floor_scene(0.6, vec![light("sun", LightKind::Directional { direction }, 2.0)]);
    let world = World::new(&valid(scene.clone()));
    let expected = 0.6 / PI * 2.0 * (-direction).dot(Vec3::Y);
    for algorithm in [Algorithm::Path, Algorithm::Whitted] {
        for target in [Vec3::ZERO, Vec3::new(3.0, 0.0, -7.0), Vec3::new(-40.0, 0.0, 2.0)] {
            let origin = Vec3::new(0.5, 2.0, 4.0);
            let got = trace(algorithm, &world, &Ray::new(origin, (target - origin).normalize()), 64);
            assert!((got.x - expected).abs() < 0.01 * expected, "{algorithm}: {got} vs {expected}");
        }
    }
}

#[test]
fn lambert_plane_under_a_point_light() {
    let position = Vec3::new(0.4, 1.5, -0.2);
    let scene = floor_scene(0.8, vec![light("bulb", LightKind::Point { position }, 5.0)]);
    let world = World::new(&valid(scene.clone()));
    for target in [Vec3::ZERO, Vec3::new(1.0, 0.0, -1.0), Vec3::new(-3.0, 0.0, 0.5)] {
        let to_light = position - target;
        let d = to_light.length();
        let expected = 0.8 / PI * 5.0 * (to_light.y / d) / (d * d);
        let origin = Vec3::new(0.0, 3.0, 3.0);
        for algorithm in [Algorithm::Path, Algorithm::Whitted] {
            let got = trace(algorithm, &world, &Ray::new(origin, (target - origin).normalize()), 64);
            assert!((got.y - expected).abs() < 0.01 * expected, "{algorithm} at {target}: {got} vs {expected}");
        }
    }
}

#[test]
fn white_furnace_stays_one_and_half_albedo_gives_half() {
    for (albedo, expected) in [(1.0f32, 1.0f64), (0.5, 0.5)] {
        let mut scene = scene(
            camera(Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO),
            vec![material("grey", lambert(albedo))],
            vec![object("ball", Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, "grey")],
            vec![],
        );
        // Uniform environment of radiance 1, the sphere fills the middle of the frame
        scene.background = Vec3::ONE;
        scene.camera.fov_y_degrees = 20.0;
        let image = render(scene, Algorithm::Path, 16);
        let centre: Vec<[f32; 3]> =
            (8..16).flat_map(|y| (12..20).map(move |x| (x, y))).map(|(x, y)| image.get(x, y)).collect();
        let mean = mean_luminance(&centre);
        assert!((mean - expected).abs() < 0.01 * expected, "albedo {albedo}: {mean}");
    }
}

/// The thesis' Phong formula by hand: ka·La + (I/d²/π)·(kd (l·n) + ks (r·v)^α).
#[test]
fn whitted_phong_sphere_matches_the_hand_computation() {
    let (ka, kd, ks, alpha) = (Vec3::new(0.2, 0.1, 0.0), Vec3::new(0.5, 0.3, 0.1), Vec3::new(0.3, 0.3, 0.3), 12.0);
    let light_position = Vec3::new(2.0, 3.0, 4.0);
    let mut scene = scene(
        camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO),
        vec![material("plastic", MaterialModel::Phong { ka, kd, ks, shininess: alpha })],
        vec![object("ball", Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, "plastic")],
        vec![light("bulb", LightKind::Point { position: light_position }, 20.0)],
    );
    scene.ambient = Vec3::splat(0.1);
    let world = World::new(&valid(scene.clone()));
    let camera = gi_studio::render::world::camera::CameraModel::new(&scene.camera, 64, 48);
    for (px, py) in [(32.0, 24.0), (36.5, 20.5), (28.0, 27.0), (34.0, 22.0)] {
        let ray = camera.pixel_ray(px, py);
        // Oracle in f64: hit point, normal, light and view vectors
        let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
        let b = o.dot(d);
        let t = -b - (b * b - (o.length_squared() - 1.0)).sqrt();
        let p = o + d * t;
        let n = p.normalize();
        let to_light = light_position.as_dvec3() - p;
        let (dist, l) = (to_light.length(), to_light.normalize());
        let v = -d;
        let r = 2.0 * l.dot(n) * n - l;
        let light = 20.0 / (dist * dist) / std::f64::consts::PI;
        let expected = (ka * 0.1).as_dvec3()
            + light * (kd.as_dvec3() * l.dot(n).max(0.0) + ks.as_dvec3() * r.dot(v).max(0.0).powf(12.0));
        let got = trace(Algorithm::Whitted, &world, &ray, 1).as_dvec3();
        assert!((got - expected).abs().max_element() < 1e-4, "pixel ({px}, {py}): {got} vs {expected}");
        assert!(expected.x > 0.05, "the chosen pixel must be lit");
    }
}

#[test]
fn spot_cone_edge_falls_where_cos_theta_says() {
    let cone = 20.0f32;
    let height = 2.0f32;
    let spot = LightKind::Spot {
        position: Vec3::new(0.0, height, 0.0),
        direction: -Vec3::Y,
        cone_angle_degrees: cone,
        falloff_exponent: 0.0,
    };
    let scene = floor_scene(0.5, vec![light("spot", spot, 10.0)]);
    let world = World::new(&valid(scene.clone()));
    let edge = height * cone.to_radians().tan();
    let origin = Vec3::new(0.0, 5.0, 0.01);
    for (radius, lit) in [(edge * 0.99, true), (edge * 1.01, false), (0.0, true), (edge * 2.0, false)] {
        let target = Vec3::new(radius, 0.0, 0.0);
        let got = trace(Algorithm::Whitted, &world, &Ray::new(origin, (target - origin).normalize()), 1);
        assert_eq!(got.x > 0.0, lit, "radius {radius} (edge {edge}): {got}");
    }
}

/// A floor under an emissive sphere of radius 1000 whose bottom is 1 above
/// it: every floor pixel holds ρ·L·(r/d)², by a t-test over replicas
/// (`detectors::mis_under_a_giant_light_holds_the_closed_form`): light
/// sampling draws only the sphere's cap over what the camera sees, and
/// multiple importance sampling leaves the rest to BSDF sampling; the sum
/// must stay unbiased.
#[test]
fn floor_under_a_giant_light_sphere() {
    if let Err(e) = detectors::mis_under_a_giant_light_holds_the_closed_form() {
        panic!("{e}");
    }
}

/// A floor in a room whose ceiling is a black sphere of radius 1e4, under a
/// light sphere of radius 600 that pokes 0.5 through it (smallpt's light
/// pokes 0.27 through a ceiling of radius 1e5). Only the cap under the
/// ceiling can light the room, and light sampling draws only that cap. Seen
/// from below, the cap's outline is the rim circle where the two spheres
/// meet, and a uniform emitter's irradiance depends only on its outline: the
/// floor gets exactly what a disc of the rim's radius a at the rim's height h
/// would give, at a distance s from its axis
/// E = πL/2 · (1 − (h² + s² − a²) / √((h² + s² + a²)² − 4a²s²)).
/// (A ceiling of radius 1e5 is placed only to ~5·10⁻³ in f32, which hides a
/// sliver of the rim from every strategy alike: 0.5% less light here.)
#[test]
fn floor_under_a_light_poking_through_the_ceiling() {
    let (ceiling, big, radius, poke) = (10.0f64, 1.0e4f64, 600.0f64, 0.5f64);
    let wall_center = Vec3::new(0.0, (ceiling - big) as f32, 0.0);
    let light_center = Vec3::new(0.0, (ceiling + radius - poke) as f32, 0.0);
    let mut scene = scene(
        camera(Vec3::new(0.0, 6.0, 6.0), Vec3::new(0.0, 0.0, 0.0)),
        vec![
            material("floor", lambert(0.5)),
            material("black", lambert(0.0)),
            material("light", MaterialModel::Emissive { radiance: Vec3::ONE }),
        ],
        vec![
            object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
            object("ceiling", Shape::Sphere { center: wall_center, radius: big as f32 }, "black"),
            object("light", Shape::Sphere { center: light_center, radius: radius as f32 }, "light"),
        ],
        vec![],
    );
    scene.camera.fov_y_degrees = 50.0;
    // The rim: |p − c_light| = r and |p − c_wall| = R meet in the plane y = h
    let (y_light, y_wall) = (light_center.y as f64, wall_center.y as f64);
    let h = ((big * big - radius * radius) / (y_light - y_wall) + y_wall + y_light) * 0.5;
    let a = (radius * radius - (h - y_light).powi(2)).sqrt();
    let radiance_at = |s2: f64| {
        let irradiance = std::f64::consts::PI / 2.0
            * (1.0 - (h * h + s2 - a * a) / ((h * h + s2 + a * a).powi(2) - 4.0 * a * a * s2).sqrt());
        0.5 / std::f64::consts::PI * irradiance
    };

    // The world samples exactly that cap: 1 − cos θ of the rim seen from the light's centre
    let camera = gi_studio::render::world::camera::CameraModel::new(&scene.camera, 32, 24);
    let (world, _) = World::for_view(&valid(scene.clone()), &camera, 32, 24);
    let cap = world.emitting_cap(1);
    let expected_cap = 1.0 - (y_light - h) / radius;
    assert!(((cap.one_minus_cos as f64) - expected_cap).abs() < 1e-3 * expected_cap, "{cap:?} vs {expected_cap}");
    assert!(cap.frame.z.y < -0.999, "the cap faces down into the room: {cap:?}");

    // 5×5 pixels around each target, each against the floor point at its centre
    let image = render(scene, Algorithm::Path, 1024);
    for target in [Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::new(-2.0, 0.0, 3.0)] {
        let p = camera.project(target).unwrap();
        let (mut got, mut expected) = (0.0, 0.0);
        for y in p.y as u32 - 2..=p.y as u32 + 2 {
            for x in p.x as u32 - 2..=p.x as u32 + 2 {
                let ray = camera.pixel_ray(x as f32 + 0.5, y as f32 + 0.5);
                let floor = ray.at(-ray.origin.y / ray.direction.y);
                got += image.get(x, y)[0] as f64;
                expected += radiance_at((floor.x as f64).powi(2) + (floor.z as f64).powi(2));
            }
        }
        assert!((got - expected).abs() < 0.01 * expected, "at {target}: {} vs {}", got / 25.0, expected / 25.0);
    }
}

/// A Lambert floor of albedo ρ under a white sky of radiance L: its
/// radiance is ρ·L (the sky fills the hemisphere above, irradiance πL),
/// found by sampling the background as a light with multiple importance
/// sampling against the BSDF (path tracing), by sampling it alone (photon
/// mapping and SPPM, whose photons find nothing more to carry here), and
/// by paths leaving the sky's disc too (light tracing, BDPT, VCM). Eight
/// replicas each, a t-test of their means at 1e-4 (t₇ = 8.0).
#[test]
fn a_floor_under_a_white_sky_reflects_its_albedo() {
    let (albedo, sky) = (0.6f32, 1.5f32);
    let mut scene = floor_scene(albedo, vec![]);
    scene.background = Vec3::splat(sky);
    let algorithms = [Algorithm::Path, Algorithm::Photon, Algorithm::Sppm, Algorithm::LightTracing, Algorithm::Bdpt];
    for algorithm in algorithms.into_iter().chain([Algorithm::Vcm]) {
        let mut s = settings(algorithm, 24, 18, 16);
        s.set_photons(10_000);
        let means: Vec<f64> =
            detectors::replicas(&scene, s, 8).iter().map(|image| mean_luminance(&image.pixels)).collect();
        if let Err(e) = detectors::t_test(&format!("{algorithm} under a sky"), &means, (albedo * sky) as f64, 1e-4) {
            panic!("{e}");
        }
    }
}

/// An empty scene under a sky is the sky, in every pixel and exactly, by
/// every algorithm: a camera ray that meets nothing sees the background
/// whole (no strategy but the camera's can reach a pinhole), and there is
/// nothing for light to bounce off. It is also the one world the eight
/// lanes do not take, so path tracing's one-at-a-time tracer draws it.
#[test]
fn an_empty_scene_is_its_sky() {
    let sky = Vec3::new(0.25, 0.5, 1.5);
    let mut scene = floor_scene(0.5, vec![]);
    scene.objects.clear();
    scene.background = sky;
    for algorithm in Algorithm::ALL {
        let (image, _) = common::render(&scene, settings(algorithm, 8, 6, 2));
        for (i, pixel) in image.pixels.iter().enumerate() {
            assert_eq!(*pixel, sky.to_array(), "{algorithm}, pixel {i}");
        }
    }
}
