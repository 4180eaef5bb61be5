//! The studio's dialogs: the file dialog, "replace this file?", "discard
//! unsaved changes?" and the offer of a crashed session's scene. Each
//! answer comes back as a command.

use std::path::{Path, PathBuf};

use eframe::egui;

use super::commands::{Action, Command};
use super::files::{file_dialog_ui, DialogPurpose, FileDialog};
use crate::scene::Scene;

#[derive(Default)]
pub struct Dialogs {
    file: Option<FileDialog>,
    /// A chosen path that exists, waiting for the user to say replace it.
    replace: Option<(DialogPurpose, PathBuf)>,
    /// What would discard unsaved edits, waiting for the user's answer.
    pending: Option<Action>,
    /// The last session's unsaved scene, offered back.
    autosave_offer: Option<Scene>,
}

impl Dialogs {
    pub fn new(autosave_offer: Option<Scene>) -> Self {
        Self { autosave_offer, ..Self::default() }
    }

    /// The file dialog for `purpose`, suggesting the document's own file
    /// (`scene_path`) or a name that says what it is for.
    pub fn open_file(&mut self, purpose: DialogPurpose, scene_path: Option<&Path>) {
        let suggestion = match purpose {
            DialogPurpose::OpenScene | DialogPurpose::SaveScene => {
                scene_path.map_or_else(|| PathBuf::from("assets/scenes/untitled.ron"), Path::to_owned)
            }
            DialogPurpose::ExportPng => PathBuf::from("render.png"),
            DialogPurpose::ExportExr => PathBuf::from("render.exr"),
            DialogPurpose::Screenshot => PathBuf::from("screenshot.png"),
            DialogPurpose::ComparisonSheet => PathBuf::from("comparison.png"),
        };
        self.file = Some(FileDialog::new(purpose, &suggestion));
    }

    pub fn ask_unsaved(&mut self, action: Action) {
        self.pending = Some(action);
    }

    pub fn offers_autosave(&self) -> bool {
        self.autosave_offer.is_some()
    }

    /// The offered scene, taken (the offer is answered).
    pub fn take_autosave(&mut self) -> Option<Scene> {
        self.autosave_offer.take()
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
                // Writing over another file is the user's call, asked once
                let own_file = purpose == DialogPurpose::SaveScene && scene_path == Some(path.as_path());
                if purpose != DialogPurpose::OpenScene && path.exists() && !own_file {
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
        if self.autosave_offer.is_some() {
            egui::Window::new("Restore unsaved scene?").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label("The last session ended with unsaved edits. Restore that scene?");
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
