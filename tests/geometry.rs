//! f32 geometry against f64 oracles (the re-spawn sweep over scales is
//! hard case 5 in hard_cases.rs).

use gi_studio::geometry::{intersect_sphere, Ray};
use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::uniform_sphere;
use glam::{DVec3, Vec3};

fn random_direction(s: &mut Sampler) -> Vec3 {
    uniform_sphere(s.next_2d())
}

/// Nearest positive sphere root in f64.
fn sphere_oracle(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<f64> {
    let d = d.normalize();
    let f = o - c;
    let b = f.dot(d);
    let disc = r * r - (f - b * d).length_squared();
    if disc < 0.0 {
        return None;
    }
    [-b - disc.sqrt(), -b + disc.sqrt()].into_iter().find(|t| *t > 0.0)
}

#[test]
fn smallpt_walls_agree_with_the_oracle_for_camera_rays() {
    let scene = gi_studio::scene::presets::preset("smallpt").unwrap().unwrap();
    let camera = gi_studio::render::world::camera::CameraModel::new(&scene.camera, 64, 48);
    let walls: Vec<(Vec3, f32)> = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            gi_studio::scene::Shape::Sphere { center, radius } if radius > 1e4 => Some((center, radius)),
            _ => None,
        })
        .collect();
    assert_eq!(walls.len(), 6);
    for y in (0..48).step_by(5) {
        for x in (0..64).step_by(5) {
            let ray = camera.pixel_ray(x as f32 + 0.5, y as f32 + 0.5);
            for (center, radius) in &walls {
                let got = intersect_sphere(&ray, *center, *radius, f32::INFINITY).map(|h| h.t as f64);
                let want =
                    sphere_oracle(ray.origin.as_dvec3(), ray.direction.as_dvec3(), center.as_dvec3(), *radius as f64);
                // f32 cannot know c = |f|² − r² better than ε|f|² when |f| ≈ r = 1e5,
                // and t = c/q inherits that over |q| ≥ |f·d|; nor hold t, of up
                // to 2e5 across a wall's ball, better than ε·t: the bound to hold.
                let f = (ray.origin - *center).as_dvec3();
                let tolerance = 2.0 * f32::EPSILON as f64 * f.length_squared() / f.dot(ray.direction.as_dvec3()).abs();
                match (got, want) {
                    (Some(g), Some(w)) => {
                        let tolerance = tolerance + 2.0 * f32::EPSILON as f64 * w;
                        assert!((g - w).abs() <= tolerance, "pixel ({x},{y}): {g} vs {w} (tolerance {tolerance})")
                    }
                    (None, None) => {}
                    other => panic!("pixel ({x},{y}): {other:?}"),
                }
            }
        }
    }
}

#[test]
fn tiny_sphere_from_ten_million_units_agrees_with_the_oracle() {
    let ray = Ray::new(Vec3::new(-1.0e7, 0.095, 0.0), Vec3::X);
    let hit = intersect_sphere(&ray, Vec3::ZERO, 0.1, f32::INFINITY).expect("hit");
    let expected_point = DVec3::new(-(0.01f64 - 0.095f64 * 0.095).sqrt(), 0.095, 0.0);
    assert!((hit.point.as_dvec3() - expected_point).length() < 1e-6, "{}", hit.point);
    assert!((hit.normal.as_dvec3() - expected_point / 0.1).length() < 1e-5);
}

#[test]
fn rays_starting_inside_find_the_far_wall_and_tangent_rays_stay_finite() {
    let mut s = Sampler::new(3, 0, 1);
    for _ in 0..1000 {
        let d = random_direction(&mut s);
        let hit = intersect_sphere(&Ray::new(Vec3::ZERO, d), Vec3::ZERO, 1.0e5, f32::INFINITY).unwrap();
        assert!((hit.t - 1.0e5).abs() < 0.1);
    }
    // A family of rays sweeping through tangency: never a NaN
    for i in 0..2000 {
        let y = 1.0 - 1.0e-3 + i as f32 * 1.0e-6;
        let ray = Ray::new(Vec3::new(-10.0, y, 0.0), Vec3::X);
        if let Some(hit) = intersect_sphere(&ray, Vec3::ZERO, 1.0, f32::INFINITY) {
            assert!(hit.point.is_finite() && hit.normal.is_finite() && hit.t.is_finite());
        }
    }
}
