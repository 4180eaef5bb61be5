//! Undo and redo over scene snapshots. A change is committed once the user
//! lets go (no drag in progress), so one drag of a slider is one step.

use crate::scene::Scene;

pub struct History {
    undo: Vec<Scene>,
    redo: Vec<Scene>,
    committed: Scene,
}

/// Enough for a session of edits; snapshots are small.
const LIMIT: usize = 500;

impl History {
    pub fn new(scene: &Scene) -> Self {
        Self { undo: Vec::new(), redo: Vec::new(), committed: scene.clone() }
    }

    /// Record `scene` as a new step if it differs from the last one and the
    /// user is not in the middle of a drag.
    pub fn observe(&mut self, scene: &Scene, interacting: bool) {
        if !interacting && *scene != self.committed {
            self.undo.push(std::mem::replace(&mut self.committed, scene.clone()));
            if self.undo.len() > LIMIT {
                self.undo.remove(0);
            }
            self.redo.clear();
        }
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    pub fn undo(&mut self, scene: &mut Scene) {
        self.observe(scene, false);
        if let Some(previous) = self.undo.pop() {
            self.redo.push(std::mem::replace(&mut self.committed, previous.clone()));
            *scene = previous;
        }
    }

    pub fn redo(&mut self, scene: &mut Scene) {
        if let Some(next) = self.redo.pop() {
            self.undo.push(std::mem::replace(&mut self.committed, next.clone()));
            *scene = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;

    #[test]
    fn a_drag_is_one_step_and_undo_redo_walk_it() {
        let original = default_scene();
        let mut scene = original.clone();
        let mut history = History::new(&scene);
        for step in 1..=10 {
            scene.camera.fov_y_degrees = 40.0 + step as f32;
            history.observe(&scene, true);
        }
        history.observe(&scene, false);
        let dragged = scene.clone();
        history.undo(&mut scene);
        assert_eq!(scene, original);
        assert!(!history.can_undo());
        history.redo(&mut scene);
        assert_eq!(scene, dragged);
        assert!(!history.can_redo());
    }
}
