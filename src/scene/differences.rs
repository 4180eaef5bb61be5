//! What differs between two versions of a scene, as a user reads it: the
//! parts that changed ("the camera", "object “glass ball”"), for a dialog
//! that offers one of them back.

use super::Scene;

/// The parts of `after` that differ from `before`, at most `limit` of them
/// named (and how many more).
pub fn differences(before: &Scene, after: &Scene, limit: usize) -> Vec<String> {
    let mut parts = Vec::new();
    let mut part = |changed: bool, name: String| {
        if changed {
            parts.push(name);
        }
    };
    part(before.camera != after.camera, "the camera".into());
    part(before.background != after.background || before.ambient != after.ambient, "the background".into());
    part(before.settings != after.settings, "the image settings".into());
    named(&mut parts, "material", &before.materials, &after.materials, |m| &m.name);
    named(&mut parts, "object", &before.objects, &after.objects, |o| &o.name);
    named(&mut parts, "light", &before.lights, &after.lights, |l| &l.name);
    if parts.len() > limit {
        let more = parts.len() - limit;
        parts.truncate(limit);
        parts.push(format!("{more} more"));
    }
    parts
}

/// Items added, removed or changed, by name (a renamed item is one removed
/// and one added).
fn named<T: PartialEq>(parts: &mut Vec<String>, kind: &str, before: &[T], after: &[T], name: impl Fn(&T) -> &String) {
    for item in after {
        match before.iter().find(|b| name(b) == name(item)) {
            None => parts.push(format!("{kind} “{}” (new)", shown(name(item)))),
            Some(old) if old != item => parts.push(format!("{kind} “{}”", shown(name(item)))),
            Some(_) => {}
        }
    }
    for item in before.iter().filter(|b| !after.iter().any(|a| name(a) == name(b))) {
        parts.push(format!("{kind} “{}” (deleted)", shown(name(item))));
    }
}

/// A name as a message shows it: at most 40 characters.
pub fn shown(name: &str) -> String {
    const MAX: usize = 40;
    match name.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}…", &name[..cut]),
        None => name.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;

    #[test]
    fn each_kind_of_change_is_named_and_the_list_is_cut() {
        let before = default_scene();
        assert!(differences(&before, &before, 8).is_empty());
        let mut after = before.clone();
        after.camera.fov_y_degrees = 50.0;
        after.objects[6].shape = crate::scene::Shape::Sphere { center: glam::Vec3::ZERO, radius: 0.1 };
        after.objects.remove(0);
        after.materials[0].name = "chalk".into();
        let parts = differences(&before, &after, 8);
        assert_eq!(
            parts,
            [
                "the camera",
                "material “chalk” (new)",
                "material “white” (deleted)",
                "object “glass ball”",
                "object “floor” (deleted)"
            ]
        );
        assert_eq!(differences(&before, &after, 2), ["the camera", "material “chalk” (new)", "3 more"]);
    }

    #[test]
    fn a_long_name_is_cut() {
        assert_eq!(shown(&"x".repeat(10_000)).chars().count(), 41);
        assert_eq!(shown("glass ball"), "glass ball");
    }
}
