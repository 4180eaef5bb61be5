//! Every warp and every light's sampling against the density it claims, by
//! Pearson's χ² (Nori's and pbrt's style): directions binned in equal solid
//! angles, points in equal areas, the expected counts integrated from the
//! pdf, not from the sampler. Each test asks p > 1e-4 (a false alarm one run
//! in 10 000 per test; the seeds are fixed, so a run is either right or
//! not). A pdf off by a factor, or a warp that bunches its samples, fails.

mod common;

use std::f32::consts::PI;

use common::stats::*;
use common::*;
use gi_studio::geometry::{intersect_sphere, intersect_triangle, Ray, SurfaceHit};
use gi_studio::render::world::light::{AreaLight, LightSource};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::*;
use gi_studio::render::world::World;
use gi_studio::scene::{presets, MaterialModel, Shape};
use glam::{Vec2, Vec3};

const SAMPLES: usize = 200_000;
const LEVEL: f64 = 1e-4;

fn assert_fits(what: &str, result: ChiSquare) {
    assert!(
        result.p_value > LEVEL,
        "{what}: χ² {:.1} with {} dof, p = {:.2e}: the samples do not follow the pdf",
        result.statistic,
        result.dof,
        result.p_value
    );
}

/// The statistics the suite decides by, held to values from tables and
/// closed forms.
#[test]
fn the_distributions_give_their_known_values() {
    assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    // χ²: the 95% point of one degree of freedom is 3.841; with two, P = e^(−x/2)
    assert!((chi_square_p_value(3.841_458_8, 1) - 0.05).abs() < 1e-6);
    assert!((chi_square_p_value(7.0, 2) - (-3.5f64).exp()).abs() < 1e-12);
    assert!((chi_square_p_value(150.0, 100) / 9.039_320_42e-4 - 1.0).abs() < 1e-6);
    // I_0.4(2, 3) = Σ_{j=2..4} C(4,j) 0.4^j 0.6^(4−j)
    assert!((beta_i(2.0, 3.0, 0.4) - 0.5248).abs() < 1e-12);
    // Student's t: 2.228 at 5% two-sided with 10 dof; 12.706 with 1
    assert!((student_t_quantile(0.05, 10.0) - 2.228_138_85).abs() < 1e-6);
    assert!((student_t_quantile(0.05, 1.0) - 12.706_204_7).abs() < 1e-5);
    assert!((normal_quantile(0.05) - 1.959_963_98).abs() < 1e-7);
    assert!((normal_quantile(1e-9) - 6.109_410_2).abs() < 1e-5);
    // Šidák: 1000 tests at family-wise 1e-3 ask 1.0005e-6 of each
    assert!((sidak(1e-3, 1000) - 1.000_500_2e-6).abs() < 1e-12);
}

#[test]
fn direction_warps_follow_their_pdfs() {
    let mut s = Sampler::new(1, 0, 77);
    let sphere = DirectionBins::sphere(16, 24);
    let cosine =
        sphere.test(SAMPLES, || Some(cosine_hemisphere(s.next_2d())), 8, |d| cosine_hemisphere_pdf(d.z) as f64);
    assert_fits("cosine hemisphere", cosine);
    let uniform = sphere.test(SAMPLES, || Some(uniform_sphere(s.next_2d())), 8, |_| 1.0 / (4.0 * PI as f64));
    assert_fits("uniform sphere", uniform);

    // Cones from a distant star's to a hemisphere's, binned over the cone
    for one_minus_cos in [1e-5f32, 0.01, 0.3, 1.0, 2.0] {
        let bins = DirectionBins::cone(Vec3::Z, one_minus_cos as f64, 10, 16);
        let inside = |d: Vec3| common::stats::one_minus_cos(d) <= one_minus_cos as f64;
        let pdf = |d: Vec3| if inside(d) { uniform_cone_pdf(one_minus_cos) as f64 } else { 0.0 };
        let cone = bins.test(SAMPLES, || Some(uniform_cone(s.next_2d(), one_minus_cos)), 8, pdf);
        assert_fits(&format!("cone 1 − cos = {one_minus_cos}"), cone);
    }

    // Power-cosine lobes, binned over the window holding all but 1e-3
    for exponent in [0.0f32, 1.0, 10.0, 100.0, 2000.0] {
        let span = 1.0 - (1e-3f64).powf(1.0 / (exponent as f64 + 1.0));
        let bins = DirectionBins::cone(Vec3::Z, span, 10, 16);
        let draw = || Some(power_cosine(s.next_2d(), exponent));
        let lobe = bins.test(SAMPLES, draw, 8, |d| power_cosine_pdf(d.z, exponent) as f64);
        assert_fits(&format!("power cosine n = {exponent}"), lobe);
    }
}

/// Points: the concentric disk in equal-area rings and sectors, the
/// triangle's barycentrics in its n² congruent sub-triangles.
#[test]
fn point_warps_are_uniform() {
    let mut s = Sampler::new(2, 0, 78);
    let (rings, sectors) = (12, 24);
    let mut observed = vec![0.0; rings * sectors];
    for _ in 0..SAMPLES {
        let p = concentric_disk(s.next_2d());
        let r2 = p.length_squared() as f64;
        assert!(r2 <= 1.0 + 1e-6, "outside the disk: {p}");
        let ring = ((r2 * rings as f64) as usize).min(rings - 1);
        let phi = (p.y as f64).atan2(p.x as f64).rem_euclid(std::f64::consts::TAU);
        let sector = ((phi / std::f64::consts::TAU * sectors as f64) as usize).min(sectors - 1);
        observed[ring * sectors + sector] += 1.0;
    }
    let expected = vec![SAMPLES as f64 / (rings * sectors) as f64; rings * sectors];
    assert_fits("concentric disk", chi_square(&observed, &expected));

    let n = 16;
    let mut observed = vec![0.0; n * n];
    for _ in 0..SAMPLES {
        let (b0, b1) = uniform_triangle(s.next_2d());
        let b2 = 1.0 - b0 - b1;
        assert!(b0 >= 0.0 && b1 >= 0.0 && b2 >= -1e-6, "outside the triangle: {b0} {b1}");
        let (x, y) = (b0 as f64 * n as f64, b1 as f64 * n as f64);
        let (i, j) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
        // Cell (i, j) of the grid holds a lower triangle and, where
        // i + j < n − 1, an upper one: n² sub-triangles in all
        let upper = x - i as f64 + y - j as f64 >= 1.0;
        let index = if upper { (n * (n + 1) / 2) + cell_index(i, j, n - 1) } else { cell_index(i, j, n) };
        observed[index.min(n * n - 1)] += 1.0;
    }
    let expected = vec![SAMPLES as f64 / (n * n) as f64; n * n];
    assert_fits("uniform triangle", chi_square(&observed, &expected));
}

/// Number of cell (i, j) among those with i + j < `size` (row by row).
fn cell_index(i: usize, j: usize, size: usize) -> usize {
    (0..i).map(|row| size - row).sum::<usize>() + j
}

/// What `light` says of the direction `d` from `at`: its pdf where the ray
/// meets its emitter first, 0 where it misses.
fn light_pdf_toward(light: &LightSource, world: &World, at: Vec3, d: Vec3) -> f64 {
    let LightSource::Area(AreaLight { object, .. }) = light else { return 0.0 };
    let ray = Ray::new(at, d);
    let hit = match world.objects[*object as usize].shape {
        gi_studio::render::world::ShapeRef::Sphere(i) => intersect_sphere(
            &ray,
            world.shapes.spheres.center(i as usize),
            world.shapes.spheres.radius(i as usize),
            f32::INFINITY,
        ),
        gi_studio::render::world::ShapeRef::Triangle(t) => {
            intersect_triangle(&ray, &world.shapes.triangles.list[t as usize].0, f32::INFINITY)
        }
        gi_studio::render::world::ShapeRef::Plane(_) | gi_studio::render::world::ShapeRef::Mesh { .. } => None,
    };
    hit.map_or(0.0, |hit| light.pdf(at, &hit) as f64)
}

/// Sampling `light` from the point `at` (normal `normal`) against its pdf,
/// over a window of directions about `axis` holding the whole light; and
/// each sample's pdf is what `pdf` says of its direction.
fn check_light(what: &str, world: &World, light: &LightSource, at: Vec3, normal: Vec3, axis: Vec3, span: f64) {
    let surface = SurfaceHit { t: 1.0, point: at, normal, error: 1e-6 };
    let mut s = Sampler::new(3, 0, 79);
    let (mut worst, mut grazing) = (0.0f64, 0);
    let bins = DirectionBins::cone(axis, span, 12, 16);
    let draw = || {
        let sample = light.sample(&surface, s.next_2d())?;
        match light_pdf_toward(light, world, at, sample.wi) {
            // The cone's very edge: the ray grazes the sphere and misses by rounding
            0.0 => grazing += 1,
            claimed => worst = worst.max((sample.pdf as f64 / claimed - 1.0).abs()),
        }
        Some(sample.wi)
    };
    let result = bins.test(SAMPLES, draw, 24, |d| light_pdf_toward(light, world, at, d));
    assert_fits(what, result);
    assert!(worst < 1e-3, "{what}: a sample's pdf differs from the pdf of its direction by {worst:.2e}");
    assert!(grazing < SAMPLES / 10_000, "{what}: {grazing} samples miss the light they sampled");
}

/// Each area light's sampling against its solid-angle pdf: a sphere seen
/// from outside (sampled by the cone it subtends), a triangle (by area),
/// and smallpt's light sphere, sampled only on its cap under the ceiling.
#[test]
fn area_lights_sample_their_solid_angle_pdfs() {
    let emissive = MaterialModel::Emissive { radiance: Vec3::splat(3.0) };
    let lights = valid(scene(
        camera(Vec3::new(0.0, 1.0, 6.0), Vec3::ZERO),
        vec![material("floor", lambert(0.5)), material("light", emissive)],
        vec![
            object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
            object("bulb", Shape::Sphere { center: Vec3::new(1.0, 3.0, -0.5), radius: 0.8 }, "light"),
            object(
                "panel",
                Shape::Triangle {
                    a: Vec3::new(-2.0, 2.0, -1.0),
                    b: Vec3::new(-1.0, 2.5, 0.5),
                    c: Vec3::new(-2.5, 1.5, 1.0),
                },
                "light",
            ),
        ],
        vec![],
    ));
    let world = World::new(&lights);
    let at = Vec3::new(0.2, 0.0, 0.3);
    let (bulb, panel) = (&world.lights[0], &world.lights[1]);
    let to_bulb = Vec3::new(1.0, 3.0, -0.5) - at;
    let sin_max = 0.8 / to_bulb.length() as f64;
    let window = 1.0 - (1.0 - sin_max * sin_max).sqrt() + 1e-3;
    check_light("sphere light", &world, bulb, at, Vec3::Y, to_bulb.normalize(), window);
    let corners = [Vec3::new(-2.0, 2.0, -1.0), Vec3::new(-1.0, 2.5, 0.5), Vec3::new(-2.5, 1.5, 1.0)];
    let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
    let axis = (centre - at).normalize();
    let window = 1.0 - corners.iter().map(|c| (*c - at).normalize().dot(axis) as f64).fold(1.0, f64::min) + 1e-3;
    check_light("triangle light", &world, panel, at, Vec3::Y, axis, window);

    // smallpt: its light's cap pokes 0.27 through the ceiling at y = 81.6
    let smallpt = presets::preset("smallpt").and_then(Result::ok).expect("the smallpt preset");
    let model = gi_studio::render::world::camera::CameraModel::new(&smallpt.camera, 64, 48);
    let (world, _) = World::for_view(&smallpt, &model, 64, 48);
    let light = world.lights.iter().find(|l| l.cap().is_some_and(|c| !c.is_whole())).expect("a capped light");
    let at = Vec3::new(40.0, 0.0, 80.0);
    let rim = Vec2::new(((600.0f32).powi(2) - (600.0f32 - 0.27).powi(2)).sqrt(), 81.6);
    let axis = (Vec3::new(50.0, 81.6, 81.6) - at).normalize();
    let window = {
        let edge = Vec3::new(50.0 + rim.x * 1.02, rim.y, 81.6) - at;
        let far = Vec3::new(50.0 - rim.x * 1.02, rim.y, 81.6) - at;
        1.0 - (edge.normalize().dot(axis).min(far.normalize().dot(axis))) as f64
    };
    check_light("smallpt's capped light", &world, light, at, Vec3::Y, axis, window);
}

/// Photons leave each light carrying its intensity: per solid angle, the
/// power of the photons a bin of directions gets is the light's
/// intensity integrated over the bin (a point light's I, a spot light's
/// I·cos^σ within its cone, a one-sided emitting triangle's L·A·cos θ).
/// A weighted χ² (`DirectionBins::weighted_test`) at p > 1e-4 and their
/// total power within 4 standard errors: photons 2% too strong, or a spot's
/// falloff applied twice, fail it.
#[test]
fn photons_leave_each_light_with_its_intensity() {
    use gi_studio::render::integrators::photon_map::emit::{emit, LightPicker};
    let (intensity, exponent, cone) = (2.5f32, 3.0f32, 35f32.to_radians());
    let spot_axis = Vec3::new(0.3, -1.0, 0.2).normalize();
    let emissive = MaterialModel::Emissive { radiance: Vec3::splat(1.5) };
    let corners = [Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), Vec3::new(0.0, 2.5, 1.0)];
    let cases = [
        ("point", gi_studio::scene::LightKind::Point { position: Vec3::new(0.0, 1.0, 0.0) }, None),
        (
            "spot",
            gi_studio::scene::LightKind::Spot {
                position: Vec3::new(0.0, 2.0, 0.0),
                direction: spot_axis,
                cone_angle_degrees: cone.to_degrees(),
                falloff_exponent: exponent,
            },
            None,
        ),
        ("triangle", gi_studio::scene::LightKind::Point { position: Vec3::ZERO }, Some(corners)),
    ];
    for (name, kind, triangle) in cases {
        let mut lit = scene(
            camera(Vec3::new(0.0, 1.0, 6.0), Vec3::ZERO),
            vec![material("floor", lambert(0.5)), material("light", emissive.clone())],
            vec![object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor")],
            vec![light(name, kind, intensity)],
        );
        if let Some([a, b, c]) = triangle {
            lit.lights.clear();
            lit.objects.push(object("panel", Shape::Triangle { a, b, c }, "light"));
        }
        let world = World::new(&valid(lit));
        let picker = LightPicker::new(&world);
        let mut s = Sampler::new(4, 0, 80);
        let draw = || emit(&world, &picker, &mut s).map(|p| (p.ray.direction, p.power.x as f64));
        let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
        let area = 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
        let (bins, density): (DirectionBins, Box<dyn Fn(Vec3) -> f64>) = match name {
            "point" => (DirectionBins::sphere(12, 16), Box::new(|_| intensity as f64)),
            "spot" => (
                DirectionBins::cone(spot_axis, 1.0 - cone.cos() as f64 + 1e-3, 12, 16),
                Box::new(|d: Vec3| {
                    let cos = d.dot(spot_axis);
                    if cos >= cone.cos() {
                        (intensity * cos.powf(exponent)) as f64
                    } else {
                        0.0
                    }
                }),
            ),
            _ => (
                DirectionBins::cone(normal, 1.0, 12, 16),
                Box::new(|d: Vec3| (1.5 * area * d.dot(normal).max(0.0)) as f64),
            ),
        };
        let (result, total) = bins.weighted_test(SAMPLES, draw, 12, density);
        assert_fits(&format!("{name} light's photons"), result);
        // |z| < 4: a false alarm one run in 16 000
        assert!(total.abs() < 4.0, "{name} light's photons carry {total:.1} standard errors too much power");
    }
}

/// The light picker over nothing to pick, and past its lights: a scene
/// with no light, or with only a dark one, has nothing to emit (no photon,
/// no light path, never a division by its zero power); two lights are
/// picked in proportion to their power, and an index past them never is.
#[test]
fn the_light_picker_picks_by_power_and_never_from_nothing() {
    use gi_studio::render::integrators::photon_map::emit::LightPicker;
    let floor = || vec![object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor")];
    let lit = |lights| {
        let scene =
            scene(camera(Vec3::new(0.0, 1.0, 6.0), Vec3::ZERO), vec![material("floor", lambert(0.5))], floor(), lights);
        LightPicker::new(&World::new(&valid(scene)))
    };
    let point = |name: &str, x: f32, intensity| {
        light(name, gi_studio::scene::LightKind::Point { position: Vec3::new(x, 1.0, 0.0) }, intensity)
    };
    for (what, picker) in [("no light", lit(vec![])), ("a dark light", lit(vec![point("dark", 0.0, 0.0)]))] {
        assert!(picker.is_empty(), "{what}: something to pick");
        assert_eq!(picker.pick(0.5), None, "{what}");
        assert_eq!(picker.probability(0), 0.0, "{what}");
    }
    let two = lit(vec![point("dim", -1.0, 1.0), point("bright", 1.0, 3.0)]);
    assert!(!two.is_empty());
    assert!((two.probability(0) - 0.25).abs() < 1e-6 && (two.probability(1) - 0.75).abs() < 1e-6);
    assert_eq!(two.probability(2), 0.0, "a light past the last");
    assert_eq!(two.pick(0.1).map(|(i, _)| i), Some(0));
    assert_eq!(two.pick(0.9).map(|(i, _)| i), Some(1));
    // A u rounded up to 1 (past every cumulative power) still picks the last light
    assert_eq!(two.pick(1.0).map(|(i, _)| i), Some(1));
}

/// A glass ball of `radius` at `center` over a floor, lit by `light` alone:
/// the world, its light picker and its caustic targets.
fn glass_ball_under(
    center: Vec3,
    radius: f32,
    light: gi_studio::scene::Light,
) -> (
    World,
    gi_studio::render::integrators::photon_map::emit::LightPicker,
    gi_studio::render::integrators::photon_map::emit::SpecularTargets,
) {
    use gi_studio::render::integrators::photon_map::emit::{LightPicker, SpecularTargets};
    let objects = vec![
        object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor"),
        object("ball", Shape::Sphere { center, radius }, "glass"),
    ];
    let glass = MaterialModel::Glass { ior: 1.5, tint: Vec3::ONE };
    let materials = vec![material("floor", lambert(0.5)), material("glass", glass)];
    let eye = camera(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO);
    let world = World::new(&valid(scene(eye, materials, objects, vec![light])));
    let (picker, targets) = (LightPicker::new(&world), SpecularTargets::of(&world));
    assert_eq!(targets.list.len(), 1, "the ball is the one caustic target");
    (world, picker, targets)
}

/// Caustic photons from a directional light leave a disc that just covers
/// the glass sphere they are aimed at, along the light: every ray passes
/// within the sphere's radius of its centre, the disc is covered uniformly
/// (E[ρ²] = r²/2; 5σ with σ² = r⁴/12/n), and every photon carries the same
/// finite power (one target, one light: the density of origins is the
/// same everywhere on the disc).
#[test]
fn directional_caustic_photons_leave_a_disc_covering_their_target() {
    use gi_studio::render::integrators::photon_map::emit::emit_toward;
    let (center, radius) = (Vec3::new(0.3, 0.5, -0.2), 0.3);
    let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
    let sun = light("sun", gi_studio::scene::LightKind::Directional { direction }, 2.0);
    let (world, picker, targets) = glass_ball_under(center, radius, sun);
    let mut s = Sampler::new(0, 0, 164);
    let (n, mut rho2_sum, mut first_power) = (20_000, 0.0f64, None);
    for _ in 0..n {
        let photon = emit_toward(&world, &picker, &targets, &mut s).expect("a photon toward the ball");
        assert!((photon.ray.direction - direction).length() < 1e-6, "along the light");
        let offset = center - photon.ray.origin;
        let rho2 = (offset - direction * offset.dot(direction)).length_squared();
        assert!(rho2 <= radius * radius * (1.0 + 1e-4), "a ray passing {} from the centre", rho2.sqrt());
        rho2_sum += (rho2 / (radius * radius)) as f64;
        let power = photon.power;
        assert!(power.is_finite() && power.min_element() > 0.0, "power {power}");
        let first = *first_power.get_or_insert(power);
        assert!((power - first).abs().max_element() <= 1e-5 * first.max_element(), "{power} against {first}");
    }
    let mean = rho2_sum / n as f64;
    let sigma = (1.0 / 12.0 / n as f64).sqrt();
    assert!((mean - 0.5).abs() < 5.0 * sigma, "E[ρ²]/r² = {mean}, σ {sigma}");
}

/// Caustic photons from a spot light (falloff exponent 0, its cone wider
/// than the ball) are aimed into the cone the ball subtends, uniformly, so
/// each carries the intensity times that cone's solid angle,
/// 2π(1 − cos θ), the inverse of the direction's pdf.
#[test]
fn spot_caustic_photons_carry_intensity_times_the_cone() {
    use gi_studio::render::integrators::photon_map::emit::emit_toward;
    let (center, radius, position) = (Vec3::new(0.0, 0.5, 0.0), 0.3, Vec3::new(0.2, 2.5, 0.1));
    let kind = gi_studio::scene::LightKind::Spot {
        position,
        direction: -Vec3::Y,
        cone_angle_degrees: 60.0,
        falloff_exponent: 0.0,
    };
    let (world, picker, targets) = glass_ball_under(center, radius, light("spot", kind, 3.0));
    let distance2 = (center - position).length_squared() as f64;
    let sin2 = (radius * radius) as f64 / distance2;
    let cone = 2.0 * std::f64::consts::PI * (1.0 - (1.0 - sin2).sqrt());
    let expected = 3.0 * cone;
    let mut s = Sampler::new(0, 0, 171);
    for _ in 0..2000 {
        let photon = emit_toward(&world, &picker, &targets, &mut s).expect("a photon toward the ball");
        assert!(
            intersect_sphere(&photon.ray, center, radius, f32::INFINITY).is_some(),
            "a photon that misses the ball"
        );
        let power = photon.power.max_element() as f64;
        assert!((power - expected).abs() < 1e-4 * expected, "power {power} against {expected}");
    }
}
