//! The presets' references, compiled into the binary as the presets are:
//! found wherever the program runs.

use super::file::parse_info;
use super::Reference;
use crate::scene::{presets, Scene};

/// (preset, EXR, metadata) of every preset.
const EMBEDDED: &[(&str, &[u8], &str)] = &[
    (
        "cornell",
        include_bytes!("../../../assets/references/cornell.exr"),
        include_str!("../../../assets/references/cornell.exr.meta.ron"),
    ),
    (
        "smallpt",
        include_bytes!("../../../assets/references/smallpt.exr"),
        include_str!("../../../assets/references/smallpt.exr.meta.ron"),
    ),
    (
        "thesis",
        include_bytes!("../../../assets/references/thesis.exr"),
        include_str!("../../../assets/references/thesis.exr.meta.ron"),
    ),
    (
        "lights",
        include_bytes!("../../../assets/references/lights.exr"),
        include_str!("../../../assets/references/lights.exr.meta.ron"),
    ),
    (
        "caustics",
        include_bytes!("../../../assets/references/caustics.exr"),
        include_str!("../../../assets/references/caustics.exr.meta.ron"),
    ),
    (
        "mirror-caustic",
        include_bytes!("../../../assets/references/mirror-caustic.exr"),
        include_str!("../../../assets/references/mirror-caustic.exr.meta.ron"),
    ),
    (
        "gap-room",
        include_bytes!("../../../assets/references/gap-room.exr"),
        include_str!("../../../assets/references/gap-room.exr.meta.ron"),
    ),
    (
        "glossy",
        include_bytes!("../../../assets/references/glossy.exr"),
        include_str!("../../../assets/references/glossy.exr.meta.ron"),
    ),
    (
        "metals",
        include_bytes!("../../../assets/references/metals.exr"),
        include_str!("../../../assets/references/metals.exr.meta.ron"),
    ),
    (
        "cornell-mesh",
        include_bytes!("../../../assets/references/cornell-mesh.exr"),
        include_str!("../../../assets/references/cornell-mesh.exr.meta.ron"),
    ),
    (
        "knot",
        include_bytes!("../../../assets/references/knot.exr"),
        include_str!("../../../assets/references/knot.exr.meta.ron"),
    ),
];

/// The compiled-in reference of `scene`, if it is a preset as shipped.
pub fn embedded(scene: &Scene) -> Option<Reference> {
    let &(name, bytes, info) = EMBEDDED
        .iter()
        .find(|(name, _, _)| presets::preset(name).and_then(Result::ok).is_some_and(|preset| *preset == *scene))?;
    let path = format!("(built in) assets/references/{name}.exr");
    let info = parse_info(info, std::path::Path::new(&format!("{path}.meta.ron"))).ok()?;
    Reference::decode(bytes, info, &path).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_has_its_reference_built_in() {
        for name in presets::names() {
            assert!(EMBEDDED.iter().any(|(n, _, _)| *n == name), "{name} has no built-in reference");
            let scene = presets::preset(name).unwrap().unwrap().into_scene();
            let reference = embedded(&scene).unwrap_or_else(|| panic!("{name}'s reference decodes"));
            assert_eq!((reference.image.width, reference.image.height), super::super::reference_size(&scene));
            assert!(reference.info.samples_per_pixel >= 1024, "{name}: a converged reference");
        }
        let mut edited = presets::preset("cornell").unwrap().unwrap().into_scene();
        edited.camera.fov_y_degrees += 1.0;
        assert!(embedded(&edited).is_none());
    }
}
