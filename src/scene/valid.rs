//! Parse, don't validate: a scene whose every value was checked, the only
//! kind the renderer takes. It is made once (by `ValidScene::new`, or by
//! loading a file) and read through `Deref`; nothing downstream checks again.

use std::ops::Deref;

use super::{Invalid, Scene};

#[derive(Clone, Debug, PartialEq)]
pub struct ValidScene(Scene);

impl ValidScene {
    /// The scene, if nothing in it is invalid; every problem otherwise.
    pub fn new(scene: Scene) -> Result<Self, Vec<Invalid>> {
        let problems = scene.validate();
        if problems.is_empty() {
            Ok(Self(scene))
        } else {
            Err(problems)
        }
    }

    /// The scene, to edit (and check again).
    pub fn into_scene(self) -> Scene {
        self.0
    }
}

impl From<ValidScene> for Scene {
    fn from(valid: ValidScene) -> Scene {
        valid.0
    }
}

impl Deref for ValidScene {
    type Target = Scene;

    fn deref(&self) -> &Scene {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;

    #[test]
    fn only_a_scene_without_problems_is_valid() {
        let scene = default_scene();
        assert_eq!(*ValidScene::new(scene.clone()).unwrap(), scene);
        let mut broken = scene;
        broken.objects[5].material = "nowhere".into();
        broken.camera.fov_y_degrees = f32::NAN;
        let problems = ValidScene::new(broken).unwrap_err();
        let fields: Vec<&str> = problems.iter().map(|p| p.field.as_str()).collect();
        assert_eq!(fields, ["camera.fov_y_degrees", "objects[5] \"mirror ball\".material"]);
    }
}
