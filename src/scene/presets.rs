//! The built-in scenes, compiled into the binary so the studio opens anywhere;
//! the same files live in `assets/scenes/` for editing and the CLI.

use std::path::Path;

use super::{parse_scene, Scene, SceneFileError, ValidScene};

/// (name, RON text) of every preset, in menu order.
pub const PRESETS: &[(&str, &str)] = &[
    ("cornell", include_str!("../../assets/scenes/cornell.ron")),
    ("smallpt", include_str!("../../assets/scenes/smallpt.ron")),
    ("thesis", include_str!("../../assets/scenes/thesis.ron")),
    ("lights", include_str!("../../assets/scenes/lights.ron")),
    ("caustics", include_str!("../../assets/scenes/caustics.ron")),
    ("mirror-caustic", include_str!("../../assets/scenes/mirror-caustic.ron")),
    ("gap-room", include_str!("../../assets/scenes/gap-room.ron")),
    ("glossy", include_str!("../../assets/scenes/glossy.ron")),
    ("metals", include_str!("../../assets/scenes/metals.ron")),
    ("cornell-mesh", include_str!("../../assets/scenes/cornell-mesh.ron")),
    ("knot", include_str!("../../assets/scenes/knot.ron")),
];

pub fn names() -> impl Iterator<Item = &'static str> {
    PRESETS.iter().map(|(name, _)| *name)
}

/// The preset called `name`, parsed and validated.
pub fn preset(name: &str) -> Option<Result<ValidScene, SceneFileError>> {
    let (name, text) = PRESETS.iter().find(|(n, _)| *n == name)?;
    Some(parse_scene(text, Path::new(&format!("assets/scenes/{name}.ron"))))
}

/// The scene the studio opens on.
pub fn default_scene() -> Scene {
    match preset("cornell") {
        Some(Ok(scene)) => scene.into_scene(),
        // Unreachable while the preset test passes; keep the studio usable anyway.
        _ => fallback_scene(),
    }
}

fn fallback_scene() -> Scene {
    use super::{Camera, ClipAlong, Light, LightKind, Material, MaterialModel, Object, SceneSettings, Shape};
    use glam::Vec3;
    Scene {
        camera: Camera {
            position: Vec3::new(0.0, 1.0, 4.0),
            look_at: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fov_y_degrees: 40.0,
            near_clip: 0.0,
            near_clip_along: ClipAlong::ViewAxis,
            aperture_radius: 0.0,
            focus_distance: 0.0,
        },
        background: Vec3::splat(0.1),
        ambient: Vec3::ZERO,
        settings: SceneSettings::default(),
        materials: vec![Material { name: "grey".into(), model: MaterialModel::Lambert { albedo: Vec3::splat(0.7) } }],
        objects: vec![Object {
            name: "ball".into(),
            shape: Shape::Sphere { center: Vec3::new(0.0, 0.5, 0.0), radius: 0.5 },
            material: "grey".into(),
        }],
        lights: vec![Light {
            name: "light".into(),
            kind: LightKind::Point { position: Vec3::new(2.0, 3.0, 2.0) },
            color: Vec3::ONE,
            intensity: 20.0,
            attenuation: Default::default(),
            enabled: true,
        }],
        meshes: Default::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_validates() {
        for name in names() {
            let scene = preset(name).expect("listed").unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!scene.objects.is_empty(), "{name}");
        }
        assert!(fallback_scene().validate().is_empty());
    }

    #[test]
    fn preset_files_on_disk_match_the_embedded_ones() {
        for (name, text) in PRESETS {
            let path = format!("{}/assets/scenes/{name}.ron", env!("CARGO_MANIFEST_DIR"));
            assert_eq!(std::fs::read_to_string(path).unwrap(), *text);
        }
    }
}
