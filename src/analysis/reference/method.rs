//! How a scene's reference is made: by which method, at which size, with
//! which seed.

use crate::render::{Algorithm, RenderSettings};
use crate::scene::{MaterialModel, Scene};

/// References are rendered with their own seed: a pane's path tracer with
/// the default seed 0 would otherwise draw the very samples the reference's
/// first passes drew, and its error would look smaller than it is.
pub const REFERENCE_SEED: u64 = 0x7265_6665_7265_6e63;

/// Samples per pixel (passes, for SPPM) of a finished reference.
pub const REFERENCE_PASSES: u32 = 4096;

/// The method a scene's reference needs, and why, as the studio says it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReferenceMethod {
    pub algorithm: Algorithm,
    pub reason: &'static str,
}

/// Path tracing where its estimate converges; vertex connection and
/// merging (consistent) where light can reach the camera through mirrors or
/// glass from a point, spot or directional light: a caustic path tracing
/// never finds, since no direction it samples can hit a delta light, and
/// BDPT not where the caustic is itself seen in a mirror (light, glass,
/// floor, mirror, camera). VCM merges those and connects the rest. (SPPM
/// did this before VCM; it carried the background's light only once the
/// background became a light.) Where only area lights or the sky shine on
/// mirrors or glass, BDPT: its light subpaths find the caustics that path
/// tracing finds only by chance, so its noise falls several times faster
/// there (docs/performance.md), and it is as unbiased.
pub fn reference_method(scene: &Scene) -> ReferenceMethod {
    let delta_light = scene.lights.iter().any(|l| l.enabled && l.intensity > 0.0 && l.color.max_element() > 0.0);
    let specular = scene.objects.iter().any(|o| {
        let model = scene.material_index(&o.material).map(|m| &scene.materials[m].model);
        model.is_some_and(MaterialModel::is_specular)
    });
    match (delta_light, specular) {
        (true, true) => ReferenceMethod {
            algorithm: Algorithm::Vcm,
            reason: "vertex connection and merging: a point-like light shines through mirrors or glass, a caustic path tracing cannot find",
        },
        (false, true) => ReferenceMethod {
            algorithm: Algorithm::Bdpt,
            reason: "bidirectional path tracing: light comes through mirrors or glass, whose caustics light subpaths find",
        },
        _ => ReferenceMethod { algorithm: Algorithm::Path, reason: "path tracing: it converges on this scene" },
    }
}

/// References are made at half the scene's size (the four-pane size):
/// a pane at full size is compared after a 2×2 box filter, which is what a
/// half-size render estimates.
pub fn reference_size(scene: &Scene) -> (u32, u32) {
    ((scene.settings.width / 2).max(1), (scene.settings.height / 2).max(1))
}

/// How `algorithm` renders a reference of `scene` at `width × height`:
/// `REFERENCE_PASSES` samples per pixel (passes, for SPPM), its own seed.
pub fn reference_settings(algorithm: Algorithm, width: u32, height: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        samples_per_pixel: Some(REFERENCE_PASSES),
        seed: REFERENCE_SEED,
        ..RenderSettings::for_algorithm(algorithm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets;

    #[test]
    fn a_point_light_through_glass_asks_for_merging_an_area_light_for_light_subpaths() {
        let method = |name: &str| reference_method(&presets::preset(name).unwrap().unwrap().into_scene()).algorithm;
        // Point lights without mirrors or glass, or no mirrors or glass
        for name in ["lights", "gap-room", "glossy"] {
            assert_eq!(method(name), Algorithm::Path, "{name}");
        }
        // Area lights through mirrors or glass
        for name in ["cornell", "smallpt", "caustics"] {
            assert_eq!(method(name), Algorithm::Bdpt, "{name}");
        }
        // The thesis' chrome ball throws the key light's caustic, under a sky or not
        assert_eq!(method("thesis"), Algorithm::Vcm);
        assert_eq!(method("mirror-caustic"), Algorithm::Vcm);
        let mut scene = presets::preset("cornell").unwrap().unwrap().into_scene();
        let point = crate::scene::LightKind::Point { position: glam::Vec3::new(0.0, 1.5, 0.0) };
        scene.lights.push(crate::scene::Light {
            name: "bulb".into(),
            kind: point,
            color: glam::Vec3::ONE,
            intensity: 2.0,
            attenuation: Default::default(),
            enabled: true,
        });
        assert_eq!(reference_method(&scene).algorithm, Algorithm::Vcm);
        scene.lights[0].enabled = false;
        assert_eq!(reference_method(&scene).algorithm, Algorithm::Bdpt);
    }
}
