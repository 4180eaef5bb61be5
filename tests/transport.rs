//! Light transport on hard cases: glass in a furnace, an analytic furnace,
//! degenerate inputs, fireflies.

mod common;

use common::detectors;
use common::*;
use gi_studio::render::world::materials::{Bsdf, Transport};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::{cosine_hemisphere, power_cosine, uniform_cone, uniform_sphere};
use gi_studio::render::{Algorithm, Method, RenderSettings};
use gi_studio::scene::{LightKind, MaterialModel, Problem, Shape};
use glam::{Vec2, Vec3};

/// Glass: a lossless ball in a white furnace reflects and transmits
/// everything (radiance 1); from inside the ball radiance is n² = 2.25;
/// total internal reflection at grazing angles.
#[test]
fn glass_conserves_energy_and_reflects_totally() {
    let mut furnace = scene(
        camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO),
        vec![material("glass", MaterialModel::Glass { ior: 1.5, tint: Vec3::ONE })],
        vec![object("ball", Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, "glass")],
        vec![],
    );
    furnace.background = Vec3::ONE;
    let outside = mean_luminance(&render(&furnace, settings(Algorithm::Path, 24, 18, 64)).0.pixels);
    assert!((outside - 1.0).abs() < 0.01, "outside: {outside}");
    furnace.camera = camera(Vec3::new(0.0, 0.0, 0.2), Vec3::new(0.0, 0.0, -1.0));
    let (image, non_finite) = render(&furnace, settings(Algorithm::Path, 24, 18, 256));
    assert_eq!(non_finite, 0);
    let inside = mean_luminance(&image.pixels);
    assert!((inside - 2.25).abs() < 0.05, "inside: {inside}");
    // Leaving glass at 80° from the normal: everything reflects
    let wo = Vec3::new(80f32.to_radians().sin(), 0.0, 80f32.to_radians().cos());
    let mut s = Sampler::new(12, 0, 12);
    for _ in 0..100 {
        let b = Bsdf::glass(1.5, Vec3::ONE).sample(wo, -Vec3::Z, &mut s, Transport::Radiance).unwrap();
        assert!(b.wi.z > 0.0 && (b.wi - Vec3::new(-wo.x, 0.0, wo.z)).length() < 1e-5);
    }
}

/// Inside a closed sphere, full global illumination converges to the
/// closed form ρ/(1 − ρ): path tracing with ρ = 0.8, where roulette decides
/// most paths, by a t-test over replicas (`detectors`); progressive photon
/// mapping and photon mapping with ρ = ½ (radiance 1) within 2.5% and 4%,
/// their bias (the gather disc reaching round the sphere's curve, fixed-k's
/// blur) plus 4σ of their noise (σ ≈ 0.4%, over seeds); Whitted gives the
/// direct light alone, ½, exactly; and SPPM, gathering over a wide disc,
/// within about 0.5% (`detectors::sppm_holds_the_furnace`).
#[test]
fn an_analytic_furnace_converges_to_its_closed_form() {
    if let Err(e) = detectors::path_tracing_holds_the_furnace() {
        panic!("{e}");
    }
    let inside = detectors::furnace_scene(0.5);
    let mut sppm = settings(Algorithm::Sppm, 16, 12, 64);
    sppm.set_photons(20_000);
    let progressive = mean_luminance(&render(&inside, sppm).0.pixels);
    assert!((progressive - 1.0).abs() < 0.025, "sppm: {progressive}");
    let mut photon = settings(Algorithm::Photon, 16, 12, 16);
    photon.set_photons(200_000);
    let mapped = mean_luminance(&render(&inside, photon).0.pixels);
    println!("furnace: SPPM {progressive:.4}, photon mapping {mapped:.4}");
    assert!((mapped - 1.0).abs() < 0.04, "photon mapping: {mapped}");
    let direct = mean_luminance(&render(&inside, settings(Algorithm::Whitted, 16, 12, 1)).0.pixels);
    assert!((direct - 0.5).abs() < 1e-3, "whitted: {direct}");
    if let Err(e) = detectors::sppm_holds_the_furnace() {
        panic!("{e}");
    }
}

/// One meaning of depth for every algorithm: the longest path in segments,
/// camera to light. In the furnace of albedo ρ = ½ (`furnace_scene`) a path
/// of n segments carries ρⁿ⁻¹ of the light, so depth d gives radiance
/// Σₙ₌₂ᵈ ρⁿ⁻¹ = 1 − ½ᵈ⁻¹ on the wall: ½ at 2, ¾ at 3, ⅞ at 4 (each step
/// 14% or more, an algorithm off by one segment is off by that much). The
/// unbiased methods and bidirectional photon mapping by a t-test over eight
/// replicas of 64 passes at 1e-4 (t₇ = 7.9; light tracing's σ ≈ 0.7%), SPPM
/// and photon mapping within their bounds in the full furnace above (their
/// blur's bias plus their noise); at depth 1 no path reaches the point
/// light, so every image is black.
#[test]
fn every_algorithm_given_the_same_depth_sees_the_same_paths() {
    let inside = detectors::furnace_scene(0.5);
    let unbiased = [Algorithm::Path, Algorithm::LightTracing, Algorithm::Bdpt, Algorithm::Bpm, Algorithm::Vcm];
    let at_depth = |algorithm: Algorithm, max_depth: u32| {
        let (passes, photons) = match algorithm {
            Algorithm::Sppm => (64, 20_000),
            Algorithm::Photon => (16, 200_000),
            _ => (64, 0),
        };
        let mut s = RenderSettings { max_depth, ..settings(algorithm, 16, 12, passes) };
        s.set_photons(photons);
        // Merges over a wide disc blur this uniform light without bias
        // (`detectors::sppm_holds_the_furnace`) and with little noise
        if let Method::Bpm(merge) = &mut s.method {
            merge.radius = 0.1;
        }
        s
    };
    for algorithm in unbiased.into_iter().chain([Algorithm::Sppm, Algorithm::Photon]) {
        let image = render(&inside, RenderSettings { samples_per_pixel: Some(4), ..at_depth(algorithm, 1) }).0;
        assert!(image.pixels.iter().flatten().all(|&c| c == 0.0), "{algorithm}, depth 1: light seen");
    }
    for max_depth in [2, 3, 4] {
        let expected = 1.0 - 0.5f64.powi(max_depth as i32 - 1);
        for algorithm in unbiased {
            let means: Vec<f64> = detectors::replicas(&inside, at_depth(algorithm, max_depth), 8)
                .iter()
                .map(|image| mean_luminance(&image.pixels))
                .collect();
            // Direct light alone is exact, but for rounding, where it comes
            // from next-event estimation
            let rounding = means.iter().all(|m| (m / expected - 1.0).abs() < 1e-5);
            let tested = detectors::t_test(&format!("{algorithm}, depth {max_depth}"), &means, expected, 1e-4);
            if let (Err(e), false) = (tested, rounding) {
                panic!("{e}");
            }
        }
        for (algorithm, bound) in [(Algorithm::Sppm, 0.025), (Algorithm::Photon, 0.04)] {
            let mean = mean_luminance(&render(&inside, at_depth(algorithm, max_depth)).0.pixels);
            println!("{algorithm}, depth {max_depth}: {mean:.4} against {expected:.4}");
            assert!((mean / expected - 1.0).abs() < bound, "{algorithm}, depth {max_depth}: {mean} against {expected}");
        }
    }
}

/// Samples with u → 1, zero-length normals and a = b = c = 0 refused,
/// spot exponents 0 and 10⁴, a light exactly on a surface.
#[test]
fn degenerate_inputs_are_refused_or_harmless() {
    let u = Vec2::splat(1.0 - f32::EPSILON / 2.0);
    for d in [cosine_hemisphere(u), uniform_sphere(u), uniform_cone(u, 0.3), power_cosine(u, 1e4)] {
        assert!(d.is_finite() && (d.length() - 1.0).abs() < 1e-4, "{d}");
    }
    let mut scene = floor_scene(0.5, vec![]);
    scene.objects[0].shape = Shape::Plane { point: Vec3::ZERO, normal: Vec3::ZERO };
    assert!(scene.validate().iter().any(|p| p.problem == Problem::ZeroLength));
    let mut scene = floor_scene(0.5, vec![light("bulb", LightKind::Point { position: Vec3::Y }, 1.0)]);
    scene.lights[0].attenuation = gi_studio::scene::Attenuation { a: 0.0, b: 0.0, c: 0.0 };
    assert!(scene.validate().iter().any(|p| p.problem == Problem::ZeroAttenuation));
    for exponent in [0.0, 1.0e4] {
        let spot = LightKind::Spot {
            position: Vec3::new(0.0, 2.0, 0.0),
            direction: -Vec3::Y,
            cone_angle_degrees: 30.0,
            falloff_exponent: exponent,
        };
        let (image, non_finite) =
            render(&floor_scene(0.5, vec![light("spot", spot, 5.0)]), settings(Algorithm::Path, 16, 12, 4));
        assert_eq!(non_finite, 0);
        assert!(image.mean()[0] > 0.0);
    }
    // A point light lying on the floor: the film stays finite
    let on_surface = floor_scene(0.5, vec![light("bulb", LightKind::Point { position: Vec3::ZERO }, 5.0)]);
    for algorithm in Algorithm::ALL {
        let mut s = settings(algorithm, 16, 12, 2);
        s.set_photons(2_000);
        render(&on_surface, s);
    }
}

/// Fireflies: a tiny bright light behind glass. The film stays finite;
/// clamping is off by default and, when asked for, visibly bounds pixels.
#[test]
fn fireflies_stay_finite_and_clamping_bounds_them() {
    let mut scene = scene(
        camera(Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 0.5, 0.0)),
        vec![
            material("floor", lambert(0.8)),
            material("glass", MaterialModel::Glass { ior: 1.5, tint: Vec3::ONE }),
            material("spark", MaterialModel::Emissive { radiance: Vec3::splat(1.0e5) }),
        ],
        vec![
            object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
            object("lens", Shape::Sphere { center: Vec3::new(0.0, 0.6, 0.0), radius: 0.5 }, "glass"),
            object("spark", Shape::Sphere { center: Vec3::new(0.0, 0.6, -0.9), radius: 0.005 }, "spark"),
        ],
        vec![],
    );
    scene.background = Vec3::splat(0.01);
    assert_eq!(RenderSettings::default().firefly_clamp, 0.0);
    let (free, non_finite) = render(&scene, settings(Algorithm::Path, 24, 18, 16));
    assert_eq!(non_finite, 0);
    let mut clamped = settings(Algorithm::Path, 24, 18, 16);
    clamped.firefly_clamp = 1.0;
    let (bounded, _) = render(&scene, clamped);
    assert!(bounded.pixels.iter().flatten().all(|c| *c <= 1.0));
    assert!(free.pixels.iter().flatten().cloned().fold(0.0, f32::max) > 1.0, "the unclamped film keeps its fireflies");
}
