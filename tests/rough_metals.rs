//! Rough metals in every algorithm: each converges to path tracing's image
//! of a Cornell box whose balls are rough metals, lit by its area light
//! and by a point light.

mod common;

use common::detectors::{mean_and_error, replicas};
use common::stats::student_t_quantile;
use common::*;
use gi_studio::render::{Algorithm, RenderSettings};
use gi_studio::scene::{presets, LightKind, MaterialModel, Metal, Scene};
use glam::Vec3;

/// The Cornell box with a rough gold ball for the glass one and an
/// anisotropic aluminium ball for the mirror; with `point`, its ceiling
/// light dimmed and a point light beside it.
fn metal_box(point: bool) -> Scene {
    let mut scene = presets::preset("cornell").expect("a preset").expect("valid").into_scene();
    for material in &mut scene.materials {
        material.model = match material.model {
            MaterialModel::Glass { .. } => MaterialModel::Conductor { metal: Metal::Gold, alpha_u: 0.2, alpha_v: 0.2 },
            MaterialModel::Mirror { .. } => {
                MaterialModel::Conductor { metal: Metal::Aluminium, alpha_u: 0.05, alpha_v: 0.4 }
            }
            MaterialModel::Emissive { radiance } if point => MaterialModel::Emissive { radiance: radiance * 0.1 },
            ref other => other.clone(),
        };
    }
    assert_eq!(scene.materials.iter().filter(|m| matches!(m.model, MaterialModel::Conductor { .. })).count(), 2);
    if point {
        let position = scene.camera.look_at + Vec3::new(0.2, 0.5, 0.1);
        scene.lights.push(light("bulb", LightKind::Point { position }, 0.6));
    }
    scene
}

/// Each image's mean luminance over `k` replicas.
fn means(scene: &Scene, settings: RenderSettings, k: u64) -> Vec<f64> {
    replicas(scene, settings, k).iter().map(|image| mean_luminance(&image.pixels)).collect()
}

/// Every unbiased algorithm's mean equals path tracing's by Welch's t-test
/// over eight replicas each (two-sided 1e-4 per comparison: a false alarm
/// one run in a thousand over the ten); photon mapping and SPPM, whose
/// blur is a bias, within 2% (measured within 1.2%, their noise near 0.3%).
/// Whitted does not see the metals' indirect light and is left out.
#[test]
fn every_algorithm_converges_to_path_tracings_image_on_rough_metals() {
    let (width, height, k) = (24, 18, 8);
    for point in [false, true] {
        let scene = metal_box(point);
        let (path, path_error) = mean_and_error(&means(&scene, settings(Algorithm::Path, width, height, 256), k));
        for algorithm in [Algorithm::LightTracing, Algorithm::Bdpt, Algorithm::Bpm, Algorithm::Vcm] {
            let spp = if algorithm == Algorithm::LightTracing { 256 } else { 64 };
            let (mean, error) = mean_and_error(&means(&scene, settings(algorithm, width, height, spp), k));
            let t = (mean - path) / (error * error + path_error * path_error).sqrt();
            let critical = student_t_quantile(1e-4, (k - 1) as f64);
            println!("point {point}, {algorithm}: {mean:.5} ± {error:.1e} against path's {path:.5} ± {path_error:.1e}");
            assert!(
                t.abs() < critical,
                "point light {point}, {algorithm}: {mean} ± {error} against {path} (t = {t:.1})"
            );
        }
        for algorithm in [Algorithm::Photon, Algorithm::Sppm] {
            let mut s = settings(algorithm, width, height, if algorithm == Algorithm::Sppm { 64 } else { 16 });
            s.set_photons(if algorithm == Algorithm::Sppm { 20_000 } else { 200_000 });
            let mean = mean_luminance(&render(&scene, s).0.pixels);
            println!("point {point}, {algorithm}: {mean:.5} against path's {path:.5}");
            assert!((mean / path - 1.0).abs() < 0.02, "point light {point}, {algorithm}: {mean} against {path}");
        }
    }
}
