//! Any scene that passes validation renders with every algorithm without a
//! panic and without a non-finite pixel: random scenes with every shape,
//! material and light kind, at awkward values.

use std::sync::Arc;

use gi_studio::render::{render_blocking, Algorithm, RenderJob, RenderSettings};
use gi_studio::scene::*;
use glam::Vec3;
use proptest::prelude::*;

fn vec3(range: f32) -> impl Strategy<Value = Vec3> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn colour(max: f32) -> impl Strategy<Value = Vec3> {
    (0.0..=max, 0.0..=max, 0.0..=max).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn material_model() -> impl Strategy<Value = MaterialModel> {
    prop_oneof![
        colour(1.0).prop_map(|albedo| MaterialModel::Lambert { albedo }),
        (colour(1.0), colour(0.5), colour(0.5), 0.0f32..5000.0)
            .prop_map(|(ka, kd, ks, shininess)| MaterialModel::Phong { ka, kd, ks, shininess }),
        (colour(1.0), colour(0.5), colour(0.5), 0.0f32..5000.0)
            .prop_map(|(ka, kd, ks, shininess)| MaterialModel::BlinnPhong { ka, kd, ks, shininess }),
        colour(1.0).prop_map(|tint| MaterialModel::Mirror { tint }),
        (0.05f32..4.0, colour(1.0)).prop_map(|(ior, tint)| MaterialModel::Glass { ior, tint }),
        colour(1000.0).prop_map(|radiance| MaterialModel::Emissive { radiance }),
    ]
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (vec3(5.0), prop_oneof![1e-4f32..0.01, 0.1f32..3.0, 100.0f32..1e5])
            .prop_map(|(center, radius)| Shape::Sphere { center, radius }),
        (vec3(5.0), vec3(1.0)).prop_map(|(point, normal)| Shape::Plane { point, normal }),
        (vec3(4.0), vec3(4.0), vec3(4.0)).prop_map(|(a, b, c)| Shape::Triangle { a, b, c }),
        // Degenerate triangles are allowed (never hit)
        vec3(4.0).prop_map(|a| Shape::Triangle { a, b: a, c: a * 2.0 }),
    ]
}

fn light_kind() -> impl Strategy<Value = LightKind> {
    prop_oneof![
        vec3(6.0).prop_map(|position| LightKind::Point { position }),
        vec3(1.0).prop_map(|direction| LightKind::Directional { direction }),
        (vec3(6.0), vec3(1.0), 0.01f32..=90.0, prop_oneof![Just(0.0f32), 0.0f32..10.0, Just(1.0e4)]).prop_map(
            |(position, direction, cone_angle_degrees, falloff_exponent)| LightKind::Spot {
                position,
                direction,
                cone_angle_degrees,
                falloff_exponent
            }
        ),
    ]
}

fn random_scene() -> impl Strategy<Value = Scene> {
    (
        (vec3(8.0), vec3(2.0), 5.0f32..170.0, 0.0f32..0.5, 0.0f32..0.3, any::<bool>()),
        colour(2.0),
        prop::collection::vec(material_model(), 1..4),
        prop::collection::vec((shape(), 0usize..4), 1..5),
        prop::collection::vec(
            (light_kind(), colour(1.0), 0.0f32..100.0, (0.0f32..2.0, 0.0f32..2.0, 0.0f32..2.0), any::<bool>()),
            0..3,
        ),
    )
        .prop_map(
            |((position, look_at, fov, near_clip, aperture, along_ray), background, models, shapes, lights)| {
                let materials: Vec<Material> = models
                    .into_iter()
                    .enumerate()
                    .map(|(i, model)| Material { name: format!("m{i}"), model })
                    .collect();
                let count = materials.len();
                Scene {
                    camera: Camera {
                        position,
                        look_at,
                        up: Vec3::Y,
                        fov_y_degrees: fov,
                        near_clip,
                        near_clip_along: if along_ray { ClipAlong::Ray } else { ClipAlong::ViewAxis },
                        aperture_radius: aperture,
                        focus_distance: 0.0,
                    },
                    background,
                    ambient: Vec3::splat(0.05),
                    settings: SceneSettings { width: 8, height: 6, exposure: 0.0 },
                    objects: shapes
                        .into_iter()
                        .enumerate()
                        .map(|(i, (shape, m))| Object {
                            name: format!("o{i}"),
                            shape,
                            material: format!("m{}", m % count),
                        })
                        .collect(),
                    materials,
                    lights: lights
                        .into_iter()
                        .enumerate()
                        .map(|(i, (kind, color, intensity, (a, b, c), enabled))| Light {
                            name: format!("l{i}"),
                            kind,
                            color,
                            intensity,
                            attenuation: Attenuation { a, b, c },
                            enabled,
                        })
                        .collect(),
                    meshes: Default::default(),
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn valid_scenes_render_finite_with_every_algorithm(scene in random_scene()) {
        prop_assume!(scene.validate().is_empty());
        // The text form round-trips too
        let text = to_ron(&scene).unwrap();
        let parsed = parse_scene(&text, std::path::Path::new("random.ron")).unwrap();
        prop_assert_eq!(&*parsed, &scene);
        let scene = Arc::new(parsed);
        for algorithm in Algorithm::ALL {
            let mut settings = RenderSettings { width: 8, height: 6, samples_per_pixel: Some(2), preview: true, ..RenderSettings::for_algorithm(algorithm) };
            settings.set_photons(500);
            if let Some(p) = settings.photon_mut() {
                (p.final_gather, p.final_gather_rays) = (true, 2);
            }
            let (image, _) = render_blocking(&RenderJob::new(scene.clone(), settings)).map_err(TestCaseError::fail)?;
            prop_assert!(image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0), "{algorithm}: a non-finite or negative pixel");
        }
    }
}
