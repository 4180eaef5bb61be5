//! The scalar `Bsdf`: what its samples carry, what its lobes integrate to.

use super::glossy::diffuse_probability;
use super::*;
use crate::render::world::sampling::uniform_sphere;
use crate::scene::Metal;

fn directional_albedo(bsdf: &Bsdf, wo: Vec3, n: usize) -> Rgb {
    let mut s = Sampler::new(0, 0, 5);
    let mut sum = Rgb::ZERO;
    for _ in 0..n {
        if let Some(b) = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance) {
            sum += b.weight;
        }
    }
    sum / n as f32
}

#[test]
fn sampled_weight_matches_eval_over_pdf() {
    let bsdfs = [
        Bsdf::phong(Vec3::splat(0.3), Vec3::splat(0.6), 20.0),
        Bsdf::blinn_phong(Vec3::splat(0.2), Vec3::splat(0.7), 50.0),
        Bsdf::conductor(Metal::Gold, 0.3, 0.3),
        Bsdf::conductor(Metal::Silver, 0.05, 0.4),
    ];
    let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
    let mut s = Sampler::new(1, 1, 1);
    for bsdf in bsdfs {
        let mut sampled = 0;
        for _ in 0..1000 {
            if let Some(b) = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance) {
                sampled += 1;
                let expected = bsdf.eval(wo, b.wi, Vec3::Z) * b.wi.z / bsdf.pdf(wo, b.wi, Vec3::Z);
                assert!((expected - b.weight).abs().max_element() < 1e-3 * (1.0 + expected.max_element()));
            }
        }
        // Only directions below the surface fail, and the lobes lie mostly above it
        assert!(sampled > 800, "{bsdf:?}: {sampled} of 1000 samples");
    }
}

/// Where `front_constant` answers, it is `eval` for every direction in
/// front, bit for bit, on either side of the surface; the lobes that
/// depend on the direction do not answer.
#[test]
fn a_front_constant_is_eval_for_every_direction_in_front() {
    let mut s = Sampler::new(2, 2, 2);
    let lambert = Bsdf::lambert(Vec3::new(0.7, 0.5, 0.2));
    for _ in 0..2000 {
        let n = uniform_sphere(s.next_2d());
        let (wo, wi) = (uniform_sphere(s.next_2d()), uniform_sphere(s.next_2d()));
        let wi = if wi.dot(n) > 0.0 { wi } else { -wi };
        let constant = lambert.front_constant(wo, n).expect("Lambert's value is one");
        assert_eq!(constant, lambert.eval(wo, wi, n), "wo {wo}, wi {wi}, n {n}");
    }
    for bsdf in [
        Bsdf::phong(Vec3::splat(0.3), Vec3::splat(0.6), 20.0),
        Bsdf::blinn_phong(Vec3::splat(0.2), Vec3::splat(0.7), 50.0),
        Bsdf::mirror(Vec3::ONE),
        Bsdf::glass(1.5, Vec3::ONE),
    ] {
        assert_eq!(bsdf.front_constant(Vec3::Z, Vec3::Z), None, "{bsdf:?}");
    }
}

#[test]
fn lambert_albedo_is_exact() {
    let a = directional_albedo(&Bsdf::lambert(Vec3::splat(0.5)), Vec3::Z, 1000);
    assert!((a - Vec3::splat(0.5)).abs().max_element() < 1e-6);
}

/// The diffuse lobe is chosen by its share of the luminance (Rec. 709).
#[test]
fn the_diffuse_lobe_is_chosen_by_its_luminance_share() {
    let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
    let share = diffuse_probability(red, green);
    assert!((share - 0.2126 / (0.2126 + 0.7152)).abs() < 1e-6, "{share}");
    let share = diffuse_probability(blue * 2.0, red);
    assert!((share - 0.1444 / (0.1444 + 0.2126)).abs() < 1e-6, "{share}");
    assert_eq!(diffuse_probability(blue, Vec3::ZERO), 1.0);
    assert_eq!(diffuse_probability(Vec3::ZERO, green), 0.0);
    assert_eq!(diffuse_probability(Vec3::ZERO, Vec3::ZERO), 1.0);
}

/// ∫ g(wi) dωi over the hemisphere about +z, by the midpoint rule in
/// (cos θ, φ) (where dω = d cos θ dφ), in f64.
fn over_the_hemisphere(g: impl Fn(Vec3) -> f64) -> f64 {
    let (rings, sectors) = (1200, 64);
    let mut sum = 0.0;
    for i in 0..rings {
        let cos = (i as f64 + 0.5) / rings as f64;
        let sin = (1.0 - cos * cos).sqrt();
        for j in 0..sectors {
            let phi = (j as f64 + 0.5) / sectors as f64 * std::f64::consts::TAU;
            sum += g(Vec3::new((sin * phi.cos()) as f32, (sin * phi.sin()) as f32, cos as f32));
        }
    }
    sum * std::f64::consts::TAU / (rings * sectors) as f64
}

/// At normal incidence every glossy lobe lies above the surface: the
/// normalised lobes reflect all they receive (ks = 1), the diffuse part
/// its kd, and the sampling pdf integrates to 1 for Phong, whose lobe is
/// about the normal, and for Blinn–Phong to the diffuse share plus the
/// half vectors within 45° of the normal, 1 − cos^(n+1)(π/4).
#[test]
fn glossy_lobes_at_normal_incidence() {
    let n = Vec3::Z;
    let luminance_share = |kd: f32, ks: f32| kd / (kd + ks);
    for exponent in [1.0f32, 10.0, 40.0] {
        for (kd, ks) in [(0.0f32, 1.0f32), (0.5, 0.0), (0.3, 0.6)] {
            let phong = Bsdf::phong(Vec3::splat(kd), Vec3::splat(ks), exponent);
            let blinn = Bsdf::blinn_phong(Vec3::splat(kd), Vec3::splat(ks), exponent);
            let pd = luminance_share(kd, ks) as f64;
            let blinn_reach = 1.0 - std::f64::consts::FRAC_1_SQRT_2.powf(exponent as f64 + 1.0);
            for (bsdf, pdf_total) in [(phong, 1.0), (blinn, pd + (1.0 - pd) * blinn_reach)] {
                let albedo = over_the_hemisphere(|wi| (bsdf.eval(n, wi, n).x * wi.z) as f64);
                let pdf = over_the_hemisphere(|wi| bsdf.pdf(n, wi, n) as f64);
                let what = format!("{bsdf:?}");
                // The quadrature's own error here is below 5e-5
                assert!((albedo - (kd + ks) as f64).abs() < 5e-4, "{what}: albedo {albedo}");
                assert!((pdf - pdf_total).abs() < 5e-4, "{what}: pdf integrates to {pdf}, not {pdf_total}");
            }
        }
    }
}

/// A glass sample says how likely its own choice was: F for the
/// reflection, 1 − F for the refraction (what a bidirectional method's
/// reverse density reads), and chooses them that often.
#[test]
fn glass_samples_carry_the_chance_of_their_lobe() {
    let glass = Bsdf::glass(1.5, Vec3::ONE);
    let mut s = Sampler::new(5, 5, 5);
    for (wo, n) in [(Vec3::new(0.6, 0.0, 0.8), Vec3::Z), (Vec3::new(0.3, 0.0, -0.953_939_2), Vec3::Z)] {
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
        let (fresnel, refracted, _) = refract(wo, facing, eta_i, eta_t);
        let refracted = refracted.expect("below the critical angle");
        let trials = 20_000;
        let mut reflections = 0;
        for _ in 0..trials {
            let b = glass.sample(wo, n, &mut s, Transport::Importance).expect("glass always scatters");
            assert!(b.delta);
            if b.wi == reflect(wo, facing) {
                reflections += 1;
                assert_eq!(b.pdf, fresnel);
            } else {
                assert_eq!((b.wi, b.pdf), (refracted, 1.0 - fresnel));
            }
        }
        // Binomial: 5 standard deviations
        let sigma = (trials as f32 * fresnel * (1.0 - fresnel)).sqrt();
        assert!(
            (reflections as f32 - trials as f32 * fresnel).abs() < 5.0 * sigma,
            "{reflections} of {trials}, F = {fresnel}"
        );
    }
}

/// Russian roulette's chance to go on: the largest reflectance, at most 1.
#[test]
fn continuation_is_the_largest_reflectance() {
    let c = |bsdf: Bsdf| bsdf.continuation();
    assert_eq!(c(Bsdf::lambert(Vec3::new(0.2, 0.7, 0.4))), 0.7);
    let (kd, ks) = (Vec3::new(0.25, 0.5, 0.125), Vec3::new(0.5, 0.125, 0.125));
    assert_eq!(c(Bsdf::phong(kd, ks, 8.0)), 0.75);
    assert_eq!(c(Bsdf::blinn_phong(Vec3::splat(0.8), Vec3::splat(0.5), 8.0)), 1.0);
    assert_eq!(c(Bsdf::glass(1.5, Vec3::new(0.9, 0.3, 0.3))), 0.9);
    assert_eq!(c(Bsdf::Black), 0.0);
}

/// Reflection only: nothing for a direction behind the surface, on
/// either side.
#[test]
fn nothing_is_reflected_from_behind() {
    let phong = Bsdf::phong(Vec3::splat(0.3), Vec3::splat(0.6), 2.0);
    let (front, behind) = (Vec3::new(0.3, 0.0, 0.95).normalize(), Vec3::new(0.3, 0.0, -0.95).normalize());
    assert!(phong.eval_pdf(front, front, Vec3::Z).1 > 0.0);
    assert_eq!(phong.eval_pdf(front, behind, Vec3::Z), (Rgb::ZERO, 0.0));
    assert_eq!(phong.eval_pdf(behind, front, Vec3::Z), (Rgb::ZERO, 0.0));
}

/// A rough metal's f is the same both ways (f(wo, wi) = f(wi, wo)), on
/// any normal; its pdf is not, and needs not be.
#[test]
fn a_rough_metal_is_reciprocal() {
    let mut s = Sampler::new(4, 4, 4);
    for metal in [Bsdf::conductor(Metal::Copper, 0.2, 0.2), Bsdf::conductor(Metal::Aluminium, 0.6, 0.1)] {
        let mut seen = 0;
        for _ in 0..5000 {
            let n = uniform_sphere(s.next_2d());
            let (wo, wi) = (uniform_sphere(s.next_2d()), uniform_sphere(s.next_2d()));
            let (wo, wi) = (if wo.dot(n) < 0.0 { -wo } else { wo }, if wi.dot(n) < 0.0 { -wi } else { wi });
            let (there, back) = (metal.eval(wo, wi, n), metal.eval(wi, wo, n));
            assert!((there - back).abs().max_element() <= 1e-4 * there.max_element(), "{there} and {back}");
            seen += (there.max_element() > 0.0) as usize;
        }
        assert!(seen > 4900, "{metal:?}: only {seen} pairs reflect");
    }
}

/// The visible normals' reflection is a density over directions above the
/// surface, less what it sends below: its pdf integrates to at most 1, and
/// to 1/(1 + α²) or more at normal incidence (the facets within 45° of
/// the normal; `tests/bsdf_statistics.rs` says why).
#[test]
fn a_rough_metals_pdf_integrates_to_at_most_one() {
    for (alpha_u, alpha_v) in [(0.2f32, 0.2f32), (0.5, 0.5), (1.0, 1.0), (0.3, 0.8)] {
        let metal = Bsdf::conductor(Metal::Gold, alpha_u, alpha_v);
        for wo in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.96, 0.28)] {
            let total = over_the_hemisphere(|wi| metal.pdf(wo, wi, Vec3::Z) as f64);
            assert!(total <= 1.0 + 1e-3, "α {alpha_u}, {alpha_v}, wo {wo}: {total}");
            let above = 1.0 / (1.0 + (alpha_u.max(alpha_v) as f64).powi(2));
            assert!(wo != Vec3::Z || total >= above - 1e-3, "α {alpha_u}, {alpha_v}: {total} below {above}");
        }
    }
}

/// Below `SMOOTH_ALPHA` on both axes a metal is polished: a delta mirror
/// whose weight is Fresnel's reflectance at that angle; the scene says so
/// too (`MaterialModel::is_specular`, what the reference picks its method by).
#[test]
fn a_polished_metal_is_a_mirror_of_fresnels_colour() {
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let mut s = Sampler::new(6, 6, 6);
    for (alpha_u, alpha_v, delta) in [(0.0f32, 0.0f32, true), (5e-4, 9e-4, true), (0.0, 0.01, false), (0.2, 0.2, false)]
    {
        let bsdf = Bsdf::conductor(Metal::Gold, alpha_u, alpha_v);
        let model = MaterialModel::Conductor { metal: Metal::Gold, alpha_u, alpha_v };
        assert_eq!((bsdf.is_specular(), model.is_specular()), (delta, delta), "α {alpha_u}, {alpha_v}");
        if delta {
            let sample = bsdf.sample(wo, Vec3::Z, &mut s, Transport::Radiance).expect("a mirror reflects");
            let (eta, k) = Metal::Gold.index();
            let fresnel: Rgb = fresnel_conductor_of(0.8f32, eta.into(), k.into()).into();
            assert_eq!((sample.wi, sample.weight, sample.delta), (reflect(wo, Vec3::Z), fresnel, true));
        }
    }
    for model in [MaterialModel::Lambert { albedo: Vec3::ONE }, MaterialModel::Mirror { tint: Vec3::ONE }] {
        assert_eq!(model.is_specular(), Bsdf::new(&model).is_specular(), "{model:?}");
    }
}
