//! The studio's dialogs: the file dialog, "replace this file?", "discard
//! unsaved changes?" and the offer of a crashed session's scene. Each
//! answer comes back as a command.

use std::path::{Path, PathBuf};

use eframe::egui;

use super::commands::{Action, Command};
use super::files::{file_dialog_ui, DialogPurpose, FileDialog};
use super::storage::AutosaveOffer;
use crate::scene::Scene;

#[derive(Default)]
pub struct Dialogs {
    file: Option<FileDialog>,
    /// A chosen path that exists, waiting for the user to say replace it.
    replace: Option<(DialogPurpose, PathBuf)>,
    /// What would discard unsaved edits, waiting for the user's answer.
    pending: Option<Action>,
    /// The last session's unsaved scene, offered back.
    autosave_offer: Option<AutosaveOffer>,
    /// Where new files are suggested: the folder last used.
    folder: PathBuf,
}

impl Dialogs {
    /// `folder`: where files are suggested until one is chosen.
    pub fn new(autosave_offer: Option<AutosaveOffer>, folder: PathBuf) -> Self {
        Self { autosave_offer, folder, ..Self::default() }
    }

    /// The file dialog for `purpose`, suggesting the document's own file
    /// (`scene_path`) or, in the folder last used, a name that says what it
    /// is for.
    pub fn open_file(&mut self, purpose: DialogPurpose, scene_path: Option<&Path>) {
        let in_folder = |name: &str| self.folder.join(name);
        let suggestion = match purpose {
            DialogPurpose::OpenScene | DialogPurpose::SaveScene => {
                scene_path.map_or_else(|| in_folder("untitled.ron"), Path::to_owned)
            }
            DialogPurpose::ExportImage { pane, algorithm, exr } => {
                let extension = if exr { "exr" } else { "png" };
                in_folder(&format!("pane{}-{}.{extension}", pane + 1, algorithm.name()))
            }
            DialogPurpose::ImportMesh => in_folder(""),
            DialogPurpose::Screenshot => in_folder("screenshot.png"),
            DialogPurpose::ComparisonSheet => in_folder("comparison.png"),
        };
        self.file = Some(FileDialog::new(purpose, &suggestion));
    }

    pub fn ask_unsaved(&mut self, action: Action) {
        self.pending = Some(action);
    }

    pub fn offers_autosave(&self) -> bool {
        self.autosave_offer.is_some()
    }

    /// What the offered scene's edits are, while it is offered.
    pub fn offered_edits(&self) -> Option<&[String]> {
        self.autosave_offer.as_ref().map(|offer| offer.edits.as_slice())
    }

    /// The offered scene, taken (the offer is answered).
    pub fn take_autosave(&mut self) -> Option<Scene> {
        self.autosave_offer.take().map(|offer| offer.scene)
    }

    /// Draw what is open; the user's answers go to `commands`.
    pub fn dialogs_ui(&mut self, ctx: &egui::Context, scene_path: Option<&Path>, commands: &mut Vec<Command>) {
        if let Some(dialog) = &mut self.file {
            let (chosen, open) = file_dialog_ui(ctx, dialog);
            let purpose = dialog.purpose;
            if !open {
                self.file = None;
            }
            if let Some(path) = chosen {
                if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
                    self.folder = folder.to_owned();
                }
                // Writing over another file is the user's call, asked once
                let own_file = purpose == DialogPurpose::SaveScene && scene_path == Some(path.as_path());
                let reads = matches!(purpose, DialogPurpose::OpenScene | DialogPurpose::ImportMesh);
                if !reads && path.exists() && !own_file {
                    self.replace = Some((purpose, path));
                } else {
                    commands.push(Command::Write(purpose, path));
                }
            }
        }
        if let Some((purpose, path)) = self.replace.clone() {
            egui::Window::new("Replace file?").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label(format!("{} already exists. Replace it?", path.display()));
                ui.horizontal(|ui| {
                    if ui.button("Replace").clicked() {
                        self.replace = None;
                        commands.push(Command::Write(purpose, path.clone()));
                    }
                    if ui.button("Cancel").clicked() {
                        self.replace = None;
                    }
                });
            });
        }
        if let Some(action) = self.pending.clone() {
            egui::Window::new("Unsaved changes").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label("The scene has changes that are not saved. Discard them?");
                ui.horizontal(|ui| {
                    if ui.button("Save").clicked() {
                        self.pending = None;
                        commands.push(Command::SaveThen(action.clone()));
                    }
                    if ui.button("Discard").clicked() {
                        self.pending = None;
                        commands.push(Command::Perform(action.clone()));
                    }
                    if ui.button("Cancel").clicked() {
                        self.pending = None;
                    }
                });
            });
        }
        if let Some(offer) = &self.autosave_offer {
            egui::Window::new("Restore unsaved scene?").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label("The last session ended with unsaved edits. Restore that scene?");
                ui.label(format!("Its edits: {}.", offer.edits.join(", ")));
                ui.horizontal(|ui| {
                    if ui.button("Restore").clicked() {
                        commands.push(Command::RestoreAutosave);
                    }
                    if ui.button("Discard").clicked() {
                        commands.push(Command::DiscardAutosave);
                    }
                });
            });
        }
    }
}
