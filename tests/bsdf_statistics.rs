//! Every BSDF's energy and sampling, by statistics.

mod common;

use common::detectors::{self, albedo_by_quadrature};
use common::stats::{ChiSquare, DirectionBins};

use gi_studio::render::world::materials::{Bsdf, Transport};
use gi_studio::render::world::rng::Sampler;
use gi_studio::scene::Metal;
use glam::Vec3;

/// A metal whose Fresnel reflectance is 1 within 4·10⁻⁶ at every angle:
/// the microfacets alone.
fn white_metal(alpha_u: f32, alpha_v: f32) -> Bsdf {
    Bsdf::conductor(Metal::Custom { eta: Vec3::ONE, k: Vec3::splat(1000.0) }, alpha_u, alpha_v)
}

/// Pearson's χ² of BSDF-sampled directions against the BSDF's pdf over
/// `bins` (`common::stats`).
fn chi_square(bsdf: &Bsdf, wo: Vec3, bins: DirectionBins) -> ChiSquare {
    let mut s = Sampler::new(14, 0, 14);
    let draw = || bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance).map(|b| b.wi).filter(|wi| wi.z > 0.0);
    bins.test(200_000, draw, 12, |wi| bsdf.pdf(wo, wi, Vec3::Z) as f64)
}

/// White furnace per material: reflected energy ≤ 1 at every angle; BSDF
/// sampling passes a χ² test against its pdf. (A metal's energy against
/// its closed form is in `a_white_rough_metal_loses_only_what_its_facets_hide`.)
#[test]
fn every_bsdf_conserves_energy_and_samples_its_pdf() {
    let bsdfs = [
        Bsdf::lambert(Vec3::ONE),
        Bsdf::phong(Vec3::splat(0.3), Vec3::splat(0.7), 20.0),
        Bsdf::phong(Vec3::ZERO, Vec3::ONE, 500.0),
        Bsdf::blinn_phong(Vec3::splat(0.4), Vec3::splat(0.6), 80.0),
        Bsdf::blinn_phong(Vec3::ZERO, Vec3::ONE, 5.0),
        Bsdf::glass(1.5, Vec3::ONE),
        white_metal(0.2, 0.2),
        white_metal(1.0, 1.0),
        white_metal(0.15, 0.5),
        Bsdf::conductor(Metal::Gold, 0.4, 0.4),
    ];
    let mut s = Sampler::new(140, 0, 140);
    for bsdf in &bsdfs {
        for theta in [0.0f32, 30.0, 60.0, 85.0] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let n = 100_000;
            let energy: f64 = (0..n)
                .filter_map(|_| bsdf.sample(wo, Vec3::Z, &mut s, Transport::Importance))
                .map(|b| b.weight.max_element() as f64)
                .sum::<f64>()
                / n as f64;
            assert!(energy <= 1.0 + 0.01, "{bsdf:?} at {theta}°: energy {energy}");
            if matches!(bsdf, Bsdf::Lambert(_) | Bsdf::Glass(_)) {
                assert!(energy > 0.99, "{bsdf:?} at {theta}°: loses energy ({energy})");
            }
            // Bins over the hemisphere, or for a lobe too sharp for them (a
            // pure Phong lobe of exponent 500 is 4° wide) a window about the
            // mirror direction holding 99.9% of it: P(cos α < c) = c^(n+1)
            let bins = match bsdf {
                Bsdf::Phong(phong) if phong.kd == Vec3::ZERO.into() && phong.exponent > 100.0 => {
                    let span = 1.0 - 0.001f64.powf(1.0 / (phong.exponent as f64 + 1.0));
                    DirectionBins::cone(Vec3::new(-wo.x, -wo.y, wo.z), span, 10, 20)
                }
                _ => DirectionBins::cone(Vec3::Z, 1.0, 10, 20),
            };
            if !matches!(bsdf, Bsdf::Glass(_)) && theta < 80.0 {
                // p > 1e-4: a false alarm one run in 10 000 per lobe and angle
                let result = chi_square(bsdf, wo, bins);
                assert!(
                    result.p_value > 1e-4,
                    "{bsdf:?} at {theta}°: χ² {:.1} with {} dof, p = {:.1e}",
                    result.statistic,
                    result.dof,
                    result.p_value
                );
            }
        }
    }
}

/// Each lobe reflects what its closed form says, and its sampling's
/// estimate of what it reflects matches the quadrature from both sides: a
/// lobe too dark, a weight that forgets a cosine or divides by the wrong
/// pdf, fails here (the energy test above only bounds Phong from above).
/// Closed forms at normal incidence: the normalised Phong lobe
/// (n+2)/(2π) cosⁿα reflects everything, a Lambert surface its albedo.
/// Bounds: 4 standard errors of the sampled mean (200 000 samples) plus the
/// quadrature's own error (< 1e-3 on a 2000² grid, checked by the closed
/// forms).
#[test]
fn every_lobe_reflects_its_closed_form_and_sampling_agrees_both_ways() {
    if let Err(e) = detectors::phong_lobes_reflect_everything() {
        panic!("{e}");
    }

    let bsdfs = [
        Bsdf::lambert(Vec3::splat(0.8)),
        Bsdf::phong(Vec3::splat(0.3), Vec3::splat(0.6), 20.0),
        Bsdf::phong(Vec3::ZERO, Vec3::ONE, 100.0),
        Bsdf::blinn_phong(Vec3::splat(0.4), Vec3::splat(0.5), 80.0),
        Bsdf::blinn_phong(Vec3::ZERO, Vec3::ONE, 5.0),
        Bsdf::conductor(Metal::Copper, 0.3, 0.3),
        Bsdf::conductor(Metal::Aluminium, 0.8, 0.2),
    ];
    let mut s = Sampler::new(7, 0, 2025);
    for bsdf in &bsdfs {
        for theta in [0.0f32, 30.0, 60.0, 80.0] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let expected = albedo_by_quadrature(bsdf, wo, 2000);
            let n = 200_000;
            let (mut sum, mut squares) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let weight = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance).map_or(0.0, |b| b.weight.x as f64);
                sum += weight;
                squares += weight * weight;
            }
            let mean = sum / n as f64;
            let standard_error = ((squares / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            assert!(
                (mean - expected).abs() < 4.0 * standard_error + 1e-3,
                "{bsdf:?} at {theta}°: sampling says {mean:.5} ± {standard_error:.1e}, quadrature {expected:.5}"
            );
        }
    }
}

/// The white furnace of a rough metal whose Fresnel reflectance is 1: what
/// it reflects is what its microfacets do not send below the horizon or
/// hide from wo or wi (single scattering: light bouncing between facets is
/// lost, as in Mitsuba's `roughconductor`). By quadrature: at most 1 at
/// every angle; at normal incidence at most 1/(1 + α²), the share of GGX
/// facets within 45° of the normal (the others reflect straight down), and
/// for α ≤ 0.3 within 5% of that (Smith's masking of wi costs little), so
/// 0.1 reflects ≥ 98.9% and 0.3 ≥ 87%; α = 1 reflects 31% at normal
/// incidence and 52% at 80° (printed). The sampled weights' mean agrees
/// with the quadrature (4 standard errors).
#[test]
fn a_white_rough_metal_loses_only_what_its_facets_hide() {
    let mut s = Sampler::new(9, 0, 99);
    for alpha in [0.05f32, 0.1, 0.3, 1.0] {
        let metal = white_metal(alpha, alpha);
        for theta in [0.0f32, 30.0, 60.0, 80.0] {
            let wo = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
            let albedo = albedo_by_quadrature(&metal, wo, 2000);
            println!("α {alpha} at {theta}°: reflects {albedo:.4}");
            assert!(albedo <= 1.0 + 1e-3, "α {alpha} at {theta}°: {albedo}");
            if theta == 0.0 {
                let above = 1.0 / (1.0 + (alpha * alpha) as f64);
                assert!(albedo <= above + 1e-3, "α {alpha}: {albedo}, more than the {above} facing up");
                assert!(alpha > 0.3 || albedo >= 0.95 * above, "α {alpha}: {albedo}, of the {above} facing up");
            }
            let n = 100_000;
            let weights: Vec<f64> = (0..n)
                .map(|_| metal.sample(wo, Vec3::Z, &mut s, Transport::Radiance).map_or(0.0, |b| b.weight.x as f64))
                .collect();
            let (mean, error) = detectors::mean_and_error(&weights);
            assert!(
                (mean - albedo).abs() < 4.0 * error + 2e-3,
                "α {alpha} at {theta}°: sampling says {mean:.5} ± {error:.1e}, quadrature {albedo:.5}"
            );
        }
    }
}
