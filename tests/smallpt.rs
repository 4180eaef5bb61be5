//! smallpt as smallpt renders it: its camera rays start 140 along
//! themselves, and no path leaves its box of radius-1e5 spheres.

mod common;

use std::sync::Arc;

use common::{settings, valid};
use gi_studio::geometry::{frame_from_z, to_world};
use gi_studio::render::integrators::next_event::PathScope;
use gi_studio::render::world::camera::CameraModel;
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::cosine_hemisphere;
use gi_studio::render::world::World;
use gi_studio::render::{render_blocking, Algorithm, RenderJob, RenderSettings};
use gi_studio::scene::{presets, ClipAlong, MaterialModel, Scene, Shape};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// smallpt's `cam.o + d*140`, with `d` normalised first, starts every ray
/// on a sphere about the eye; on the plane 140 along the view axis the top
/// rows would start above the ceiling (y ≈ 81.9 > 81.6) and look straight
/// into the light (radiance 12). The room's ceiling there is below 1.
#[test]
fn smallpts_top_rows_show_the_ceiling_not_the_light() {
    let scene = presets::preset("smallpt").unwrap().unwrap().into_scene();
    assert_eq!(scene.camera.near_clip_along, ClipAlong::Ray);
    let top_rows_max = |scene| {
        let (image, _) =
            render_blocking(&RenderJob::new(Arc::new(valid(scene)), settings(Algorithm::Path, 512, 384, 16)))
                .expect("renders");
        image.pixels[..3 * 512].iter().flatten().fold(0.0f32, |m, &c| m.max(c))
    };
    let brightest = top_rows_max(scene.clone());
    assert!(brightest <= 3.0, "a top-row pixel at {brightest}");
    // The check can fail: measured on the view axis the light shows
    let mut on_plane = scene;
    on_plane.camera.near_clip_along = ClipAlong::ViewAxis;
    let brightest = top_rows_max(on_plane);
    assert!(brightest >= 10.0, "the light's radiance 12 in the top rows, found {brightest}");
}

/// Paths of up to eight diffuse bounces from smallpt's camera, off every
/// surface alike (all that matters here is where the walls are): how many
/// leave the box, found by missing everything or by meeting a wall from
/// outside (its near side, where its outward normal faces the ray). With
/// `held`, the paths meet the walls as the renderer's do; without, as a
/// plain nearest hit does.
fn escapes(paths: u64, held: bool) -> u64 {
    let scene = valid(presets::preset("smallpt").unwrap().unwrap().into_scene());
    let camera = CameraModel::new(&scene.camera, 512, 384);
    let (world, _) = World::for_view(&scene, &camera, 512, 384);
    let walls: Vec<u32> =
        (world.shapes.spheres.list.iter()).filter(|sphere| sphere.radius > 1e4).map(|sphere| sphere.object).collect();
    assert_eq!(walls.len(), 6);
    const CHUNK: u64 = 100_000;
    (0..paths.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut escaped = 0;
            for index in chunk * CHUNK..((chunk + 1) * CHUNK).min(paths) {
                let mut sampler = Sampler::new(index, 0, 2026);
                let film = sampler.next_2d() * Vec2::new(512.0, 384.0);
                let mut ray = camera.generate_ray(film, Vec2::ZERO);
                let scope = PathScope::new(&world, ray.origin);
                assert!(scope.held, "smallpt's camera rays start inside every wall");
                for _ in 0..8 {
                    let found = if held { scope.intersect(&ray) } else { world.intersect(&ray, f32::INFINITY) };
                    let Some(hit) = found else {
                        escaped += 1;
                        break;
                    };
                    if walls.contains(&hit.object) && hit.surface.normal.dot(ray.direction) < 0.0 {
                        escaped += 1;
                        break;
                    }
                    let n = hit.surface.normal;
                    let facing = if n.dot(ray.direction) > 0.0 { -n } else { n };
                    let local = cosine_hemisphere(sampler.next_2d());
                    let [x, y, z] = frame_from_z(facing.into());
                    ray = hit.surface.spawn_ray(Vec3::from(to_world([x, y, z], local.into())));
                }
            }
            escaped
        })
        .sum()
}

/// Where two of smallpt's radius-1e5 walls meet, f32 puts their hits within
/// rounding of each other (±0.07), and a plain nearest hit sends about one
/// path in 4000 out of the box, where it sees the outside of the radius-600
/// light. Paths inside every wall meet the walls only on their way out:
/// none of 10⁷ leaves.
#[test]
fn no_path_leaves_smallpts_box() {
    let plain = escapes(1_000_000, false);
    assert!(plain >= 50, "the check finds escapes: {plain} of 10⁶ with a plain nearest hit");
    assert_eq!(escapes(10_000_000, true), 0);
}

/// smallpt's room with its balls made diffuse: the walls' part of the
/// image without the glass ball's caustic, whose rare bright paths would
/// take 30 times the samples to average as well.
fn smallpt_diffuse() -> Scene {
    let mut scene = presets::preset("smallpt").unwrap().unwrap().into_scene();
    for material in &mut scene.materials {
        if matches!(material.model, MaterialModel::Mirror { .. } | MaterialModel::Glass { .. }) {
            material.model = MaterialModel::Lambert { albedo: Vec3::splat(0.75) };
        }
    }
    scene
}

/// That room built of six planes where its walls are spheres of radius
/// 1e5: the same room to within the walls' sag (0.05 at the far corners),
/// the same light.
fn smallpt_of_planes() -> Scene {
    let mut scene = smallpt_diffuse();
    let planes = [
        ("left wall", Vec3::new(1.0, 0.0, 0.0), Vec3::X),
        ("right wall", Vec3::new(99.0, 0.0, 0.0), -Vec3::X),
        ("back wall", Vec3::ZERO, Vec3::Z),
        ("front wall", Vec3::new(0.0, 0.0, 170.0), -Vec3::Z),
        ("floor", Vec3::ZERO, Vec3::Y),
        ("ceiling", Vec3::new(0.0, 81.6, 0.0), -Vec3::Y),
    ];
    for (name, point, normal) in planes {
        let wall = scene.objects.iter_mut().find(|o| o.name == name).expect("smallpt's walls");
        wall.shape = Shape::Plane { point, normal };
    }
    scene
}

/// The mean luminance of a render of `scene` with `seed`, pixel by pixel.
fn luminance(scene: &Scene, seed: u64) -> Vec<f64> {
    let settings = RenderSettings { seed, ..settings(Algorithm::Path, 64, 48, 256) };
    let (image, _) = render_blocking(&RenderJob::new(Arc::new(valid(scene.clone())), settings)).expect("renders");
    image.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).collect()
}

/// Measured before the walls held their paths, the sphere-walled room
/// rendered 0.55% brighter in mean than the plane-walled one (the paths
/// that left it saw the outside of the light, and the hits' 0.07 error
/// set the offsets of every ray off a wall); the planes' room agrees with
/// smallpt's own double-precision render. Now they agree within 0.2%. The
/// two rooms are rendered on the same random streams, so the noise they
/// share (the light's edge, half in a pixel) cancels in their difference;
/// its σ comes from two such pairs (0.02% of the mean at 256 spp), and
/// the test asks that 0.2% be over four of them.
#[test]
fn smallpts_sphere_walls_and_a_room_of_planes_agree_in_mean() {
    let (spheres, planes) = (smallpt_diffuse(), smallpt_of_planes());
    let pairs = [1, 2].map(|seed| (luminance(&spheres, seed), luminance(&planes, seed)));
    let differences: Vec<Vec<f64>> = pairs.iter().map(|(s, p)| s.iter().zip(p).map(|(s, p)| s - p).collect()).collect();
    let n = differences[0].len() as f64;
    let difference = differences.iter().flatten().sum::<f64>() / (2.0 * n);
    // (a − b)²/2 estimates a pixel's variance in one pair; the mean of two
    // pairs over n pixels has Σ var / (2n²)
    let spread: f64 = differences[0].iter().zip(&differences[1]).map(|(a, b)| (a - b).powi(2) / 2.0).sum();
    let sigma = (spread / (2.0 * n * n)).sqrt();
    let level = pairs.iter().flat_map(|(_, p)| p).sum::<f64>() / (2.0 * n);
    let tolerance = 0.002 * level;
    assert!(4.0 * sigma < tolerance, "the renders are too noisy to tell: σ {sigma:.2e} against {tolerance:.2e}");
    assert!(
        difference.abs() < tolerance,
        "spheres − planes {:.3}% of the mean (σ {:.3}%)",
        100.0 * difference / level,
        100.0 * sigma / level
    );
}
