//! Photon maps and SPPM on their edge cases.

mod common;

use std::f32::consts::PI;
use std::sync::Arc;

use common::*;
use gi_studio::analysis::metrics::{rel_mse, RelMseOptions};
use gi_studio::render::integrators::photon_map::maps::{estimate, QueryStats};
use gi_studio::render::integrators::photon_map::{Neighbours, Photon, PhotonKdTree};
use gi_studio::render::world::materials::Bsdf;
use gi_studio::render::{Algorithm, LinearImage, RenderJob};
use gi_studio::scene::presets;
use glam::Vec3;

/// Photon-map estimates on awkward maps stay finite: 0 photons, k > n,
/// all photons at one point (r = 0), fewer than 8 found, photons from behind.
#[test]
fn awkward_photon_maps_give_finite_estimates() {
    let bsdf = Bsdf::lambert(Vec3::splat(0.5));
    let (p, n) = (Vec3::ZERO, Vec3::Y);
    let mut neighbours = Neighbours::new(50);
    let mut stats = QueryStats::default();
    let down = |at: Vec3| Photon::new(at, -Vec3::Y, [1.0; 3]);
    let maps = [
        PhotonKdTree::build(Vec::new()),
        PhotonKdTree::build((0..5).map(|i| down(Vec3::new(i as f32 * 0.01, 0.0, 0.0))).collect()),
        PhotonKdTree::build((0..500).map(|_| down(Vec3::ZERO)).collect()),
        PhotonKdTree::build(
            (0..500).map(|i| Photon::new(Vec3::new(i as f32 * 1e-4, 0.0, 0.0), Vec3::Y, [1.0; 3])).collect(),
        ),
    ];
    let results: Vec<Vec3> =
        maps.iter().map(|m| estimate(m, p, n, n, &bsdf, 50, 0.1, &mut neighbours, &mut stats)).collect();
    assert!(results.iter().all(|r| r.is_finite()));
    assert_eq!(results[0], Vec3::ZERO);
    // Five photons within the radius: density over the whole disc of radius 0.1
    let expected = 0.5 / PI * 5.0 / (PI * 0.01);
    assert!((results[1].x - expected).abs() < 1e-3 * expected);
    // All at the query point: r = 0, no division by zero
    assert_eq!(results[2], Vec3::ZERO);
    // Every photon arrived from behind the surface
    assert_eq!(results[3], Vec3::ZERO);
}

/// SPPM after thousands of passes: radius positive and finite.
#[test]
fn sppm_radii_stay_positive_over_thousands_of_passes() {
    let scene = presets::preset("cornell").unwrap().unwrap();
    let mut s = settings(Algorithm::Sppm, 4, 3, 2000);
    s.set_photons(500);
    let session = gi_studio::render::RenderSession::new(gi_studio::render::Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(RenderJob::new(Arc::new(valid(scene)), s));
    let mut last_radius = f32::INFINITY;
    for event in session.events().iter() {
        match event {
            gi_studio::render::RenderEvent::PassFinished { generation: g, stats } if g == generation => {
                let r = stats.photon.mean_radius;
                assert!(
                    r > 0.0 && r.is_finite() && r <= last_radius * (1.0 + 1e-6),
                    "pass {}: radius {r}",
                    stats.passes
                );
                last_radius = r;
            }
            gi_studio::render::RenderEvent::Finished { image, .. } => {
                assert!(image.pixels.iter().flatten().all(|c| c.is_finite()));
                break;
            }
            _ => {}
        }
    }
    assert!(last_radius < f32::INFINITY);
}

/// Photon mapping's bias: fixed-k photon mapping's error plateaus while
/// SPPM's keeps falling — a plateau well below a black image's error (a
/// renderer that draws nothing plateaus too).
#[test]
fn photon_mapping_plateaus_while_sppm_converges() {
    let scene = presets::preset("caustics").unwrap().unwrap();
    let path = format!("{}/assets/references/caustics.exr", env!("CARGO_MANIFEST_DIR"));
    let reference = LinearImage::load(std::path::Path::new(&path)).unwrap().downsample(8);
    let error = |algorithm: Algorithm, passes: u32| {
        let mut s = settings(algorithm, reference.width, reference.height, passes);
        s.set_photons(20_000);
        rel_mse(&render(&scene, s).0, &reference, RelMseOptions::default()).unwrap()
    };
    let (photon_early, photon_late) = (error(Algorithm::Photon, 8), error(Algorithm::Photon, 128));
    let (sppm_early, sppm_late) = (error(Algorithm::Sppm, 8), error(Algorithm::Sppm, 128));
    assert!(photon_late > 0.5 * photon_early, "photon mapping kept converging: {photon_early} → {photon_late}");
    let black = LinearImage::new(reference.width, reference.height);
    let black_error = rel_mse(&black, &reference, RelMseOptions::default()).unwrap();
    assert!(photon_late < 0.1 * black_error, "photon mapping's plateau {photon_late}, a black image's {black_error}");
    assert!(sppm_late < 0.5 * sppm_early, "SPPM stalled: {sppm_early} → {sppm_late}");
}
