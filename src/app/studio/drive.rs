//! What the binary and the tests read of the studio and drive it by: the
//! scene, the panes, the reference, the status, and the actions a user
//! takes through the menus (open, export, promote, restart).

use std::path::Path;
use std::sync::{Arc, Mutex};

use super::StudioApp;
use crate::app::export::export_image;
use crate::app::inspector::Selection;
use crate::app::panes::Panes;
use crate::app::references::References;
use crate::app::status::Messages;
use crate::app::storage::{remember, StateFile};
use crate::scene::{load_scene, Scene};

impl StudioApp {
    pub fn scene(&self) -> &Scene {
        self.document.scene()
    }

    /// Edit the scene as the inspector does (a new revision).
    pub fn edit_scene(&mut self, edit: impl FnOnce(&mut Scene)) {
        edit(self.document.scene_mut());
        self.document.changed();
    }

    pub fn panes(&self) -> &Panes {
        &self.panes
    }

    pub fn panes_mut(&mut self) -> &mut Panes {
        &mut self.panes
    }

    /// The scene's reference, wherever it comes from.
    pub fn references(&self) -> &References {
        &self.references
    }

    pub fn references_mut(&mut self) -> &mut References {
        &mut self.references
    }

    pub fn selection(&self) -> Selection {
        self.selection
    }

    /// What the status bar says: the last error (bad file, failed save…), or news.
    pub fn messages(&self) -> &Messages {
        &self.messages
    }

    /// Whether rendering is paused (the window is minimised).
    pub fn is_paused(&self) -> bool {
        self.paused
    }

    /// Whether the last session's unsaved scene is being offered back.
    pub fn offers_autosave(&self) -> bool {
        self.dialogs.offers_autosave()
    }

    /// The slot where a failed headless screenshot leaves its error.
    pub fn exit_error(&self) -> Arc<Mutex<Option<String>>> {
        self.capture.exit_error()
    }

    /// Keep the state in `file`: written every `interval` while the studio
    /// runs (`storage::SAVE_INTERVAL` in the window), and when it closes.
    pub fn keep_state_in(&mut self, file: StateFile, interval: std::time::Duration) {
        self.state.keep_in(file, interval);
    }

    /// Add a line to the status bar.
    pub fn notice(&mut self, message: &str) {
        self.messages.notice(message);
    }

    /// Render every pane afresh with the scene as it stands (after their
    /// settings changed).
    pub fn restart_all(&mut self) {
        self.references.set_panes(self.panes.count());
        self.document.check();
        if let Some(scene) = self.document.valid().cloned() {
            self.panes.restart_all(&scene);
        }
        // A new document counts its revisions from 1 again
        self.referenced_revision = 0;
        self.follow_with_reference();
    }

    /// Let the reference follow the scene's revision, if it is new and valid.
    pub(super) fn follow_with_reference(&mut self) {
        let revision = self.document.revision();
        if revision == self.referenced_revision {
            return;
        }
        if let Some(scene) = self.document.valid().cloned() {
            self.referenced_revision = revision;
            self.references.follow(&scene);
        }
    }

    /// Make pane `index`'s image the reference.
    pub fn promote_pane(&mut self, index: usize) {
        let Some(pane) = self.panes.list().get(index) else { return };
        let promoted = self.references.promote(index, pane.algorithm(), &pane.state().image);
        self.messages.report(promoted, || format!("Pane {}'s image is the reference now", index + 1));
    }

    /// Open a scene file; a broken one leaves the scene being edited as it was.
    pub fn open_path(&mut self, path: &Path) {
        match load_scene(path) {
            Ok(scene) => {
                self.replace_scene(scene.into_scene(), Some(path.to_owned()), true);
                remember(&mut self.recent, path);
                self.messages.error = None;
                self.messages.say(format!("Opened {}", path.display()));
            }
            Err(e) => self.messages.fail(e),
        }
    }

    /// Save pane `index`'s current image (.png tone-mapped, .exr linear).
    pub fn export_pane(&mut self, index: usize, path: &Path) {
        let Some(pane) = self.panes.list().get(index) else { return };
        let exported = export_image(&pane.state().image, pane.exposure(), path);
        self.messages.report(exported, || format!("Exported {}", path.display()));
    }
}
