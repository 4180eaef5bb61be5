//! Light an algorithm cannot see. A point or spot light inside a glass ball
//! reaches the rest of the scene only through the glass, along paths that
//! the methods tracing from the camera alone never find: no direction they
//! sample meets a point, and a shadow ray toward it meets the glass. Path
//! tracing and Whitted render such a scene as if the light were off; the
//! methods that trace from the lights see it. (The enclosing shapes looked
//! at are spheres, the one closed shape a scene has.)

use crate::render::settings::Algorithm;
use crate::scene::{shown_name, LightKind, MaterialModel, Scene, Shape};

/// One line for each enabled light that `algorithm` cannot see in `scene`:
/// the light, the glass it sits in, and the algorithms that can see it.
pub fn unseen_lights(scene: &Scene, algorithm: Algorithm) -> Vec<String> {
    if algorithm.traces_from_lights() {
        return Vec::new();
    }
    let seeing: Vec<&str> = Algorithm::ALL.iter().filter(|a| a.traces_from_lights()).map(|a| a.label()).collect();
    let mut lines = Vec::new();
    for light in scene.lights.iter().filter(|l| l.enabled) {
        let position = match light.kind {
            LightKind::Point { position } | LightKind::Spot { position, .. } => position,
            LightKind::Directional { .. } => continue,
        };
        let glass = scene.objects.iter().find(|object| {
            let material = scene.material_index(&object.material).map(|m| &scene.materials[m].model);
            let inside = match object.shape {
                Shape::Sphere { center, radius } => (position - center).length() < radius,
                Shape::Plane { .. } | Shape::Triangle { .. } | Shape::Mesh { .. } => false,
            };
            inside && matches!(material, Some(MaterialModel::Glass { .. }))
        });
        if let Some(glass) = glass {
            lines.push(format!(
                "light “{}” is inside the glass of “{}”: {} cannot see its light ({} can)",
                shown_name(&light.name),
                shown_name(&glass.name),
                algorithm.label(),
                seeing.join(", ")
            ));
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;
    use crate::scene::{Attenuation, Light};

    fn with_bulb_at(position: glam::Vec3) -> Scene {
        let mut scene = default_scene();
        scene.lights.push(Light {
            name: "bulb".into(),
            kind: LightKind::Point { position },
            color: glam::Vec3::ONE,
            intensity: 5.0,
            attenuation: Attenuation::default(),
            enabled: true,
        });
        scene
    }

    #[test]
    fn a_light_in_the_glass_ball_is_unseen_by_the_camera_side_methods_only() {
        // The Cornell box's glass ball: centre (0.45, 0.35, 0.2), radius 0.35
        let scene = with_bulb_at(glam::Vec3::new(0.45, 0.35, 0.2));
        for algorithm in Algorithm::ALL {
            let lines = unseen_lights(&scene, algorithm);
            if matches!(algorithm, Algorithm::Path | Algorithm::Whitted) {
                assert_eq!(lines.len(), 1, "{algorithm:?}");
                assert!(lines[0].starts_with("light “bulb” is inside the glass of “glass ball”"), "{}", lines[0]);
                assert!(lines[0].contains("Vertex connection and merging"), "{}", lines[0]);
            } else {
                assert!(lines.is_empty(), "{algorithm:?} sees it");
            }
        }
        // Outside the ball, in the mirror ball (nothing gets out), or off
        let mut off = with_bulb_at(glam::Vec3::new(0.45, 0.35, 0.2));
        off.lights[0].enabled = false;
        for scene in
            [with_bulb_at(glam::Vec3::new(0.0, 1.5, 0.0)), with_bulb_at(glam::Vec3::new(-0.45, 0.35, -0.35)), off]
        {
            assert!(unseen_lights(&scene, Algorithm::Path).is_empty());
        }
    }
}
