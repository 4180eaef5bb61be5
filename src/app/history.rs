//! Undo and redo over scene snapshots, each with its revision (so undoing
//! back to the saved state is clean again). A change is committed once the
//! user lets go (no drag in progress), so one drag of a slider is one step.

use crate::scene::Scene;

pub struct History {
    undo: Vec<(Scene, u64)>,
    redo: Vec<(Scene, u64)>,
    committed: (Scene, u64),
}

/// Enough for a session of edits; snapshots are small.
const LIMIT: usize = 500;

impl History {
    pub fn new(scene: &Scene, revision: u64) -> Self {
        Self { undo: Vec::new(), redo: Vec::new(), committed: (scene.clone(), revision) }
    }

    /// Record `scene` as a new step if its revision is new and the user is
    /// not in the middle of a drag.
    pub fn observe(&mut self, scene: &Scene, revision: u64, interacting: bool) {
        if !interacting && revision != self.committed.1 {
            self.undo.push(std::mem::replace(&mut self.committed, (scene.clone(), revision)));
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

    /// Step back: `scene` and `revision` become the previous step's.
    pub fn undo(&mut self, scene: &mut Scene, revision: &mut u64) {
        self.observe(scene, *revision, false);
        if let Some(previous) = self.undo.pop() {
            self.redo.push(std::mem::replace(&mut self.committed, previous.clone()));
            (*scene, *revision) = previous;
        }
    }

    pub fn redo(&mut self, scene: &mut Scene, revision: &mut u64) {
        if let Some(next) = self.redo.pop() {
            self.undo.push(std::mem::replace(&mut self.committed, next.clone()));
            (*scene, *revision) = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;

    #[test]
    fn a_drag_is_one_step_and_undo_redo_walk_it_with_its_revisions() {
        let original = default_scene();
        let mut scene = original.clone();
        let mut revision = 1;
        let mut history = History::new(&scene, revision);
        for step in 1..=10 {
            scene.camera.fov_y_degrees = 40.0 + step as f32;
            revision += 1;
            history.observe(&scene, revision, true);
        }
        history.observe(&scene, revision, false);
        let (dragged, dragged_revision) = (scene.clone(), revision);
        history.undo(&mut scene, &mut revision);
        assert_eq!((&scene, revision), (&original, 1));
        assert!(!history.can_undo());
        history.redo(&mut scene, &mut revision);
        assert_eq!((&scene, revision), (&dragged, dragged_revision));
        assert!(!history.can_redo());
    }
}
