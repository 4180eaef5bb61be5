//! Opening and saving scenes without a desktop portal: a small in-app
//! dialog with a path field and the scene files it can see.

use std::path::{Path, PathBuf};

use eframe::egui;

use crate::render::Algorithm;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogPurpose {
    OpenScene,
    SaveScene,
    /// A mesh file (OBJ or PLY) to add to the scene.
    ImportMesh,
    /// Pane `pane`'s image, made by `algorithm`, as PNG (display) or EXR (linear).
    ExportImage {
        pane: usize,
        algorithm: Algorithm,
        exr: bool,
    },
    Screenshot,
    ComparisonSheet,
}

impl DialogPurpose {
    fn title(self) -> String {
        match self {
            DialogPurpose::OpenScene => "Open scene".into(),
            DialogPurpose::SaveScene => "Save scene as".into(),
            DialogPurpose::ImportMesh => "Import mesh (OBJ, PLY)".into(),
            DialogPurpose::ExportImage { pane, algorithm, exr } => {
                let format = if exr { "EXR, linear" } else { "PNG" };
                format!("Export pane {}'s image ({}) as {format}", pane + 1, algorithm.label())
            }
            DialogPurpose::Screenshot => "Save window screenshot (PNG)".into(),
            DialogPurpose::ComparisonSheet => "Export comparison sheet (PNG)".into(),
        }
    }
}

pub struct FileDialog {
    pub purpose: DialogPurpose,
    pub path: String,
}

impl FileDialog {
    pub fn new(purpose: DialogPurpose, suggestion: &Path) -> Self {
        Self { purpose, path: suggestion.display().to_string() }
    }
}

/// Scene files beside the current path and among the presets.
fn candidates(current: &str) -> Vec<PathBuf> {
    let mut folders = vec![PathBuf::from("assets/scenes")];
    if let Some(parent) = Path::new(current).parent().filter(|p| !p.as_os_str().is_empty()) {
        folders.insert(0, parent.to_owned());
    }
    let mut files: Vec<PathBuf> = folders
        .iter()
        .filter_map(|f| std::fs::read_dir(f).ok())
        .flatten()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files.dedup();
    files
}

/// Draw the dialog; returns the chosen path once confirmed, and whether it
/// is still open.
pub fn file_dialog_ui(ctx: &egui::Context, dialog: &mut FileDialog) -> (Option<PathBuf>, bool) {
    let mut chosen = None;
    let mut open = true;
    let mut cancelled = false;
    egui::Window::new(dialog.purpose.title()).collapsible(false).resizable(true).open(&mut open).show(ctx, |ui| {
        ui.horizontal(|ui| {
            ui.label("Path");
            let field = ui.add(egui::TextEdit::singleline(&mut dialog.path).desired_width(360.0));
            if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                chosen = Some(PathBuf::from(&dialog.path));
            }
        });
        if matches!(dialog.purpose, DialogPurpose::OpenScene | DialogPurpose::SaveScene) {
            egui::ScrollArea::vertical().max_height(200.0).show(ui, |ui| {
                for file in candidates(&dialog.path) {
                    if ui.selectable_label(false, file.display().to_string()).clicked() {
                        dialog.path = file.display().to_string();
                    }
                }
            });
        }
        ui.horizontal(|ui| {
            let verb = match dialog.purpose {
                DialogPurpose::OpenScene => "Open",
                DialogPurpose::ImportMesh => "Import",
                _ => "Save",
            };
            if ui.button(verb).clicked() {
                chosen = Some(PathBuf::from(&dialog.path));
            }
            if ui.button("Cancel").clicked() {
                cancelled = true;
            }
        });
    });
    (chosen.clone(), open && !cancelled && chosen.is_none())
}
