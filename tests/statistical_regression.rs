//! Renders against the stored references, pixel by pixel.

mod common;

use common::*;
use gi_studio::render::{Algorithm, LinearImage};
use gi_studio::scene::presets;

/// Per-pixel Z-test of `replicas` independent renders against `reference`
/// with Šidák correction (as Mitsuba 3 tests its renders): the smallest
/// corrected p-value's z, and the critical z.
fn z_test(replicas: &[LinearImage], reference: &LinearImage) -> (f64, f64, String) {
    let k = replicas.len() as f64;
    let pixels = reference.pixels.len() * 3;
    let mut worst = 0.0f64;
    let mut at = String::new();
    for i in 0..reference.pixels.len() {
        for c in 0..3 {
            let values: Vec<f64> = replicas.iter().map(|r| r.pixels[i][c] as f64).collect();
            let mean = values.iter().sum::<f64>() / k;
            let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
            let expected = reference.pixels[i][c] as f64;
            let standard_error = (variance / k).sqrt().max(1e-4 * expected.abs().max(1e-3));
            let z = (mean - expected).abs() / standard_error;
            if z > worst {
                worst = z;
                at = format!("pixel {} channel {c}: mean {mean:.4} ± {standard_error:.4}, reference {expected:.4}", i);
            }
        }
    }
    // Šidák: per-test α so that the family-wise α is 1e-3, as a two-sided z
    let alpha = 1.0 - (1.0 - 1e-3f64).powf(1.0 / pixels as f64);
    (worst, inverse_normal_tail(alpha / 2.0), at)
}

/// z with P(Z > z) = p, by bisection on the complementary error function.
fn inverse_normal_tail(p: f64) -> f64 {
    let tail = |z: f64| 0.5 * erfc(z / std::f64::consts::SQRT_2);
    let (mut lo, mut hi) = (0.0, 40.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Numerical Recipes' erfc (relative error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Statistical regression: low-spp path-traced renders against the
/// stored reference, per pixel, by a Z-test with Šidák correction. A bias
/// (here a 3% scale) fails it; the noise does not.
///
/// Only presets without caustics: under cornell's, smallpt's and caustics'
/// glass balls a pixel's samples are heavy-tailed (rare, bright caustic
/// paths), so 4096 samples underestimate both its mean and its variance and
/// the test would fail on noise (seen: |z| ≈ 13 under cornell's glass ball,
/// while the whole image's mean agrees with the reference to 0.05%). Those
/// presets are covered by the convergence benchmark instead.
#[test]
fn low_spp_renders_agree_with_the_references_pixel_by_pixel() {
    for name in ["thesis", "lights"] {
        let scene = presets::preset(name).unwrap().unwrap();
        let path = format!("{}/assets/references/{name}.exr", env!("CARGO_MANIFEST_DIR"));
        let full = LinearImage::load(std::path::Path::new(&path)).expect("the stored reference");
        let factor = 8;
        let reference = full.downsample(factor);
        let replicas: Vec<LinearImage> = (0..32)
            .map(|seed| {
                let mut s = settings(Algorithm::Path, reference.width, reference.height, 128);
                s.seed = 1000 + seed;
                render(&scene, s).0
            })
            .collect();
        let (z, critical, at) = z_test(&replicas, &reference);
        assert!(
            z < critical,
            "{name}: worst |z| {z:.2} ≥ {critical:.2} at {at}: the path tracer disagrees with its reference"
        );
        let biased: Vec<LinearImage> = replicas
            .iter()
            .map(|r| LinearImage { pixels: r.pixels.iter().map(|p| p.map(|c| c * 1.03)).collect(), ..r.clone() })
            .collect();
        let (z, critical, _) = z_test(&biased, &reference);
        assert!(z > critical, "{name}: a 3% bias went unnoticed (|z| {z:.2} < {critical:.2})");
    }
}
