//! What a menu, a dialog or a key asks of the studio: collected while a
//! frame is drawn and applied once after it, so no drawing code reaches
//! into the studio's state.

use std::path::PathBuf;

use super::files::DialogPurpose;

/// Something that would discard unsaved edits: asked about first.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    NewFromPreset(String),
    Open(PathBuf),
    Quit,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Do it, asking first if it would discard unsaved edits.
    Request(Action),
    /// Do it: the user said the edits may go.
    Perform(Action),
    OpenDialog(DialogPurpose),
    /// Save to the document's file, or ask where.
    Save,
    /// Save, then do it if nothing is left unsaved.
    SaveThen(Action),
    /// A path the file dialog chose (and, if it existed, the user agreed
    /// to replace), for what the dialog was for.
    Write(DialogPurpose, PathBuf),
    /// Add a mesh file's triangles to the scene as an object.
    ImportMesh(PathBuf),
    Undo,
    Redo,
    SetPanes(usize),
    Show(Panel, bool),
    RestoreAutosave,
    DiscardAutosave,
}

/// The parts of the window a user can show and hide.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Panel {
    Plots,
    Difference,
    Debug,
}

/// Which of the hideable panels are shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Shown {
    pub plots: bool,
    pub difference: bool,
    pub debug: bool,
}

impl Shown {
    pub fn set(&mut self, panel: Panel, on: bool) {
        match panel {
            Panel::Plots => self.plots = on,
            Panel::Difference => self.difference = on,
            Panel::Debug => self.debug = on,
        }
    }
}
