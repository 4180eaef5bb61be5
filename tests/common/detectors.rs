//! The statistical tests that decide whether an image is right, each a
//! function: its own test file asserts it stays quiet on the right code,
//! and `tests/injected_bugs.rs` that it fires on a renderer with a known
//! bug (`gi_studio::faults`). Each says what it compares, the noise it must
//! admit (its σ, from replicas where the variance is estimated, with
//! Student's t for it) and so its false-alarm rate.
#![allow(dead_code)]

use std::f32::consts::PI;

use super::stats::{sidak, student_t_quantile};
use super::*;
use gi_studio::analysis::reference::embedded;
use gi_studio::render::world::materials::Bsdf;
use gi_studio::render::{Algorithm, LinearImage, RenderEvent, RenderSession, Workers};
use gi_studio::scene::{presets, LightKind, MaterialModel, Scene, Shape};
use glam::Vec3;

/// Mean and standard error of the mean of `values`.
pub fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (variance / k).sqrt())
}

/// One-sample t-test of `values` against `expected` at two-sided level
/// `alpha`: Err says by how much it failed.
pub fn t_test(what: &str, values: &[f64], expected: f64, alpha: f64) -> Result<(), String> {
    let (mean, error) = mean_and_error(values);
    let t = (mean - expected) / error;
    let critical = student_t_quantile(alpha, values.len() as f64 - 1.0);
    println!("{what}: {mean:.5} ± {error:.2e} against {expected:.5}, t = {t:.2} (critical {critical:.2})");
    if t.abs() < critical {
        Ok(())
    } else {
        Err(format!("{what}: {mean:.5} ± {error:.2e} against {expected:.5} (t = {t:.1}, critical {critical:.1})"))
    }
}

/// `scene` rendered `replicas` times with seeds 1000, 1001…
pub fn replicas(scene: &Scene, mut settings: gi_studio::render::RenderSettings, replicas: u64) -> Vec<LinearImage> {
    (0..replicas)
        .map(|k| {
            settings.seed = 1000 + k;
            render(scene, settings.clone()).0
        })
        .collect()
}

/// ∫ f(wo, wi) cos θᵢ dωᵢ by the midpoint rule on an n × n grid in
/// (cos θ, φ): a figure that owes nothing to sampling or pdfs.
pub fn albedo_by_quadrature(bsdf: &Bsdf, wo: Vec3, n: usize) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        let cos = (i as f64 + 0.5) / n as f64;
        let sin = (1.0 - cos * cos).sqrt();
        for j in 0..n {
            let phi = (j as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
            let wi = Vec3::new((sin * phi.cos()) as f32, (sin * phi.sin()) as f32, cos as f32);
            sum += bsdf.eval(wo, wi, Vec3::Z).x as f64 * cos;
        }
    }
    sum * std::f64::consts::TAU / (n * n) as f64
}

/// The normalised Phong lobe (n+2)/(2π) cosⁿα reflects everything at
/// normal incidence, for n = 1, 5, 20, 100: by quadrature on a 2000² grid
/// (its own error < 1e-4 here, checked against Lambert's albedo), so a
/// bound of 1e-3 has no false alarms; a lobe 3% too dark fails it.
pub fn phong_lobes_reflect_everything() -> Result<(), String> {
    let lambert = albedo_by_quadrature(&Bsdf::lambert(Vec3::splat(0.6)), Vec3::Z, 2000);
    if (lambert - 0.6).abs() > 1e-4 {
        return Err(format!("the quadrature itself is off: Lambert 0.6 reflects {lambert}"));
    }
    for exponent in [1.0, 5.0, 20.0, 100.0] {
        let phong = Bsdf::phong(Vec3::ZERO, Vec3::ONE, exponent);
        let albedo = albedo_by_quadrature(&phong, Vec3::Z, 2000);
        if (albedo - 1.0).abs() > 1e-3 {
            return Err(format!("the Phong lobe of exponent {exponent} reflects {albedo}, not 1"));
        }
    }
    Ok(())
}

/// SPPM's mean gather radius on the caustics preset (40×30, 20 000 photons
/// a pass) after 8 and after 64 passes.
pub fn sppm_radii(alpha: f32) -> (f32, f32) {
    let scene = presets::preset("caustics").unwrap().unwrap();
    let mut sppm = settings(Algorithm::Sppm, 40, 30, 64);
    sppm.set_photons(20_000);
    sppm.sppm_mut().unwrap().alpha = alpha;
    let session = RenderSession::new(Workers::shared().unwrap(), None).unwrap();
    let generation = session.start(gi_studio::render::RenderJob::new(std::sync::Arc::new(scene), sppm));
    let (mut early, mut late) = (0.0, 0.0);
    for event in session.events().iter() {
        match event {
            RenderEvent::PassFinished { generation: g, stats } if g == generation => {
                assert!(stats.photon.mean_radius > 0.0 && stats.photon.mean_radius.is_finite());
                match stats.passes {
                    8 => early = stats.photon.mean_radius,
                    64 => late = stats.photon.mean_radius,
                    _ => {}
                }
            }
            RenderEvent::Finished { generation: g, .. } if g == generation => break,
            _ => {}
        }
    }
    (early, late)
}

/// SPPM's radius shrinks as it must: with α = 2/3 a pixel's radius² falls
/// like n^−(1−α), so the mean radius from 8 to 64 passes by about
/// (1/8)^(1/6) ≈ 0.71 (measured 0.73, fixed seeds); a radius that never
/// shrinks stays at 1. Below 0.85 passes.
pub fn sppm_radius_shrinks() -> Result<(), String> {
    let (early, late) = sppm_radii(2.0 / 3.0);
    println!("SPPM's mean radius from 8 to 64 passes: × {:.3}", late / early);
    if late < 0.85 * early {
        Ok(())
    } else {
        Err(format!("SPPM's mean radius went from {early} after 8 passes to {late} after 64"))
    }
}

/// A floor of albedo ½ under an emissive sphere of radius 1000 whose
/// bottom is 1 above it: every floor pixel's radiance is ½·L·(r/d)², d its
/// distance to the sphere's centre (the sphere is above the horizon). The
/// light is larger than what the camera sees, so light sampling draws only
/// its cap over that region and multiple importance sampling leaves the
/// rest to BSDF sampling: the two weights must sum to one. The statistic is
/// each replica's mean of (pixel / closed form) over the floor; 16 replicas
/// of 64 spp, t-test at 1e-4 (t₁₅ = 5.2): a false alarm one run in 10 000.
pub fn mis_under_a_giant_light_holds_the_closed_form() -> Result<(), String> {
    let radius = 1000.0f32;
    let center = Vec3::new(0.0, radius + 1.0, 0.0);
    let mut scene = scene(
        camera(Vec3::new(0.0, 0.6, 2.0), Vec3::new(0.0, 0.0, -0.5)),
        vec![material("floor", lambert(0.5)), material("sky", MaterialModel::Emissive { radiance: Vec3::ONE })],
        vec![
            object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
            object("sky", Shape::Sphere { center, radius }, "sky"),
        ],
        vec![],
    );
    scene.camera.fov_y_degrees = 30.0;
    let (width, height) = (32, 24);
    let camera = gi_studio::render::world::camera::CameraModel::new(&scene.camera, width, height);
    // The closed form at every pixel whose centre sees the floor well inside it
    let floor: Vec<(usize, f64)> = (0..width * height)
        .filter_map(|i| {
            let ray = camera.pixel_ray((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
            let t = -ray.origin.y / ray.direction.y;
            (t > 0.0 && t < 20.0).then(|| {
                let d = (center - ray.at(t)).length() as f64;
                (i as usize, 0.5 * (radius as f64 / d).powi(2))
            })
        })
        .collect();
    let ratios: Vec<f64> = replicas(&scene, settings(Algorithm::Path, width, height, 64), 16)
        .iter()
        .map(|image| floor.iter().map(|&(i, e)| image.pixels[i][0] as f64 / e).sum::<f64>() / floor.len() as f64)
        .collect();
    t_test("floor under a giant light, pixel over closed form", &ratios, 1.0, 1e-4)
}

/// Inside a closed sphere of radius 1 and albedo ρ, a point light of
/// intensity π at the centre: the radiance everywhere on the wall is
/// ρ/(1 − ρ) (direct ρ·E/π with E = π, plus the uniform indirect light
/// ρ·L). With ρ = 0.8 paths bounce five times on average, so Russian
/// roulette decides most of them. 16 replicas of 16 spp at 16×12; their
/// mean radiances' t-test at 1e-4 (t₁₅ = 5.2).
pub fn furnace_scene(albedo: f32) -> Scene {
    let mut inside = scene(
        camera(Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.0, 0.0, -1.0)),
        vec![material("inside", lambert(albedo))],
        vec![object("shell", Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, "inside")],
        vec![light("centre", LightKind::Point { position: Vec3::ZERO }, PI)],
    );
    inside.camera.fov_y_degrees = 60.0;
    inside
}

pub fn path_tracing_holds_the_furnace() -> Result<(), String> {
    let albedo = 0.8;
    let means: Vec<f64> = replicas(&furnace_scene(albedo), settings(Algorithm::Path, 16, 12, 16), 16)
        .iter()
        .map(|image| mean_luminance(&image.pixels))
        .collect();
    let expected = albedo as f64 / (1.0 - albedo as f64);
    t_test("path tracing in the furnace", &means, expected, 1e-4)
}

/// SPPM in the furnace of albedo ρ = 0.8 (`furnace_scene`), against the
/// closed form at its depth d, ρ(1 − ρᵈ⁻¹)/(1 − ρ) (a path of n segments
/// carries ρⁿ⁻¹). Photons carry four fifths of it, so a density estimate 2%
/// too high moves the mean by 1.6%. Gathered from radius 0.1 of the
/// sphere's 1 down: the part of a sphere inside a ball of radius r about a
/// point on it has area πr² exactly (Archimedes), so a wide disc blurs this
/// uniform light without bias and brings the noise of the image's mean
/// down to about 0.06%; only photons that graze the curve behind the
/// disc's edge are missed by the front test, a bias that grows like r²
/// (−0.06% at 0.15, none seen at 0.1). 8 replicas of 64 passes of 20 000
/// photons at 16×12; their means' t-test at 1e-4 (t₇ = 7.9: about ±0.45%).
pub fn sppm_holds_the_furnace() -> Result<(), String> {
    let albedo = 0.8f64;
    let mut sppm = settings(Algorithm::Sppm, 16, 12, 64);
    sppm.set_photons(20_000);
    if let Some(s) = sppm.sppm_mut() {
        s.initial_radius = 0.1;
    }
    let depth = sppm.max_depth as i32;
    let means: Vec<f64> =
        replicas(&furnace_scene(albedo as f32), sppm, 8).iter().map(|image| mean_luminance(&image.pixels)).collect();
    let expected = albedo * (1.0 - albedo.powi(depth - 1)) / (1.0 - albedo);
    t_test("SPPM in the furnace", &means, expected, 1e-4)
}

/// Two triangles: the quad a, b, c, d (counter-clockwise seen from its front).
pub fn quad(name: &str, [a, b, c, d]: [Vec3; 4], material: &str) -> [gi_studio::scene::Object; 2] {
    [
        object(&format!("{name} 1"), Shape::Triangle { a, b, c }, material),
        object(&format!("{name} 2"), Shape::Triangle { a, b: c, c: d }, material),
    ]
}

/// A box of side 2 open at the top and the front, of triangles (so finite:
/// a sky's photons leave from outside it), a diffuse ball in it, under a
/// white sky and no other light.
pub fn open_box_under_a_sky() -> Scene {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut objects: Vec<gi_studio::scene::Object> = [
        quad("floor", [v(-1., 0., 1.), v(1., 0., 1.), v(1., 0., -1.), v(-1., 0., -1.)], "white"),
        quad("back", [v(-1., 0., -1.), v(1., 0., -1.), v(1., 2., -1.), v(-1., 2., -1.)], "white"),
        quad("left", [v(-1., 0., 1.), v(-1., 0., -1.), v(-1., 2., -1.), v(-1., 2., 1.)], "red"),
        quad("right", [v(1., 0., -1.), v(1., 0., 1.), v(1., 2., 1.), v(1., 2., -1.)], "green"),
    ]
    .into_iter()
    .flatten()
    .collect();
    objects.push(object("ball", Shape::Sphere { center: v(0.2, 0.5, -0.2), radius: 0.5 }, "white"));
    let mut sky = scene(
        camera(v(0.0, 1.4, 4.0), v(0.0, 0.8, 0.0)),
        vec![
            material("white", lambert(0.7)),
            material("red", MaterialModel::Lambert { albedo: Vec3::new(0.7, 0.2, 0.2) }),
            material("green", MaterialModel::Lambert { albedo: Vec3::new(0.2, 0.7, 0.2) }),
        ],
        objects,
        vec![],
    );
    sky.background = Vec3::ONE;
    sky
}

/// A Cornell box with the mirror and glass balls made diffuse.
pub fn diffuse_cornell() -> Scene {
    let mut scene = presets::preset("cornell").unwrap().unwrap().into_scene();
    for material in &mut scene.materials {
        if matches!(material.model, MaterialModel::Mirror { .. } | MaterialModel::Glass { .. }) {
            material.model = MaterialModel::Lambert { albedo: Vec3::splat(0.6) };
        }
    }
    scene
}

/// Photon mapping's mean luminance on the diffuse Cornell box (40×30,
/// 10⁶ global photons, k = 100, 64 passes) against path tracing's at 2048
/// spp, within 0.8%. relMSE < 0.02 admits a uniform power error of
/// 10–14%; this does not admit photons 5% too strong, which move the mean
/// by 1.45% (photons carry only the indirect light). The σ of the two
/// means' difference is about 0.2% (the reference's noise and the photons',
/// over seeds), so the bound is 4σ: a false alarm about one run in 16 000;
/// measured on the right code +0.30% (fixed seeds: the same every run).
/// The bias of photon mapping's density estimate is in that 0.30%.
pub fn photon_mapping_holds_path_tracings_energy() -> Result<(), String> {
    let scene = diffuse_cornell();
    let mut reference_settings = settings(Algorithm::Path, 40, 30, 2048);
    reference_settings.seed = 5;
    let reference = render(&scene, reference_settings).0;
    let mut photon = settings(Algorithm::Photon, 40, 30, 64);
    photon.seed = 5;
    let p = photon.photon_mut().unwrap();
    p.global_photons = 1_000_000;
    p.k_nearest = 100;
    let image = render(&scene, photon).0;
    let (mean, expected) = (mean_luminance(&image.pixels), mean_luminance(&reference.pixels));
    let deviation = mean / expected - 1.0;
    println!("photon mapping's mean against path tracing's: {:+.3}%", deviation * 100.0);
    if deviation.abs() < 0.008 {
        Ok(())
    } else {
        Err(format!(
            "photon mapping's mean {mean:.5} against path tracing's {expected:.5} ({:+.2}%)",
            deviation * 100.0
        ))
    }
}

/// Path tracing on preset `name`, pixel by pixel against its built-in
/// 4096-spp reference (8×8 blocks): 32 replicas of 128 spp; each pixel and
/// channel's t = (mean − reference)/√(s²/32 + Var(reference)), the
/// reference's variance from its own EXR layer; the critical t from
/// Student's t with 31 dof at Šidák's level for a family-wise false alarm
/// of 1e-3 over every pixel and channel (as Mitsuba 3 tests its renders,
/// with the variance estimated, so t, not z).
pub fn path_tracing_agrees_with_its_reference(name: &str) -> Result<(), String> {
    let scene = presets::preset(name).unwrap().unwrap();
    let reference = embedded(&scene).expect("a built-in reference");
    let factor = 8;
    let mean_ref = reference.image.downsample(factor);
    // The mean of factor² pixel means has 1/factor² of their mean variance
    let variance_ref = reference.variance.as_ref().expect("its variance").downsample(factor);
    let blocks = (factor * factor) as f64;
    let runs = replicas(&scene, settings(Algorithm::Path, mean_ref.width, mean_ref.height, 128), 32);
    let tests = mean_ref.pixels.len() * 3;
    let critical = student_t_quantile(sidak(1e-3, tests), runs.len() as f64 - 1.0);
    let mut worst = (0.0f64, String::new());
    for i in 0..mean_ref.pixels.len() {
        for c in 0..3 {
            let values: Vec<f64> = runs.iter().map(|r| r.pixels[i][c] as f64).collect();
            let (mean, error) = mean_and_error(&values);
            let expected = mean_ref.pixels[i][c] as f64;
            let spread = (error * error + variance_ref.pixels[i][c] as f64 / blocks).sqrt();
            let t = (mean - expected).abs() / spread.max(1e-6 * expected.abs().max(1e-3));
            if t > worst.0 {
                worst = (t, format!("pixel {i} channel {c}: {mean:.4} ± {spread:.4} against {expected:.4}"));
            }
        }
    }
    println!("{name}: worst |t| {:.2} (critical {critical:.2}) at {}", worst.0, worst.1);
    if worst.0 < critical {
        Ok(())
    } else {
        Err(format!("{name}: worst |t| {:.1} ≥ {critical:.1} at {}", worst.0, worst.1))
    }
}

/// A render ends, with its image or with an error, and its session serves
/// the next: a bug that panics on a render worker fails its job (it used
/// to leave `render_blocking` waiting for ever, the session holding a
/// sender of its own). Fires (Err) when a render fails; quiet on the right
/// code, where both renders finish.
pub fn renders_end_and_sessions_go_on() -> Result<(), String> {
    let scene = std::sync::Arc::new(valid(presets::preset("cornell").and_then(Result::ok).expect("cornell")));
    let job = RenderJob::new(scene, settings(Algorithm::Path, 8, 6, 1));
    let workers = Workers::shared().ok_or("no workers")?;
    let session = RenderSession::new(workers, None).map_err(|e| e.to_string())?;
    for _ in 0..2 {
        let generation = session.start(job.clone());
        loop {
            match session.events().recv().map_err(|e| e.to_string())? {
                RenderEvent::Finished { generation: g, .. } if g == generation => break,
                RenderEvent::Failed { generation: g, message } if g == generation => return Err(message),
                _ => {}
            }
        }
    }
    Ok(())
}
