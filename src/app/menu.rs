//! The menu bar: File, Edit, View, Help. It reads a view of the studio and
//! returns what the user chose as commands.

use std::path::{Path, PathBuf};

use eframe::egui;

use super::commands::{Action, Command, Panel, Shown};
use super::files::DialogPurpose;
use crate::render::Algorithm;
use crate::scene::presets;

/// What the menus show.
pub struct MenuView<'a> {
    pub can_undo: bool,
    pub can_redo: bool,
    pub recent: &'a [PathBuf],
    /// Each pane's algorithm, in order.
    pub panes: Vec<Algorithm>,
    pub shown: Shown,
    /// The document's file, and whether it has unsaved edits.
    pub file: Option<(&'a Path, bool)>,
}

pub fn menu_bar_ui(ui: &mut egui::Ui, view: &MenuView, commands: &mut Vec<Command>) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| file_menu_ui(ui, view, commands));
        ui.menu_button("Edit", |ui| {
            if ui.add_enabled(view.can_undo, egui::Button::new("Undo").shortcut_text("Ctrl+Z")).clicked() {
                commands.push(Command::Undo);
                ui.close();
            }
            if ui.add_enabled(view.can_redo, egui::Button::new("Redo").shortcut_text("Ctrl+Shift+Z")).clicked() {
                commands.push(Command::Redo);
                ui.close();
            }
        });
        ui.menu_button("View", |ui| {
            for count in [1, 2, 4] {
                let label = format!("{count} pane{}", if count == 1 { "" } else { "s" });
                if ui.radio(view.panes.len() == count, label).clicked() {
                    commands.push(Command::SetPanes(count));
                    ui.close();
                }
            }
            ui.separator();
            for (panel, shown, label) in [
                (Panel::Plots, view.shown.plots, "Plots"),
                (Panel::Difference, view.shown.difference, "Difference view"),
                (Panel::Debug, view.shown.debug, "Debug overlay (frame time)"),
            ] {
                let mut on = shown;
                if ui.checkbox(&mut on, label).changed() {
                    commands.push(Command::Show(panel, on));
                }
            }
        });
        ui.menu_button("Help", |ui| {
            ui.label("Drag: orbit · Shift+drag: pan · Scroll: dolly · Click: select");
            ui.label("Ctrl+scroll: zoom the images · Ctrl+drag: pan them · F: whole images");
            ui.label("Ctrl+Z / Ctrl+Shift+Z: undo / redo · Ctrl+S: save · Ctrl+O: open");
            ui.label("Drop a .ron file on the window to open it, an .obj or .ply to import it.");
            ui.separator();
            let algorithms: Vec<&str> = Algorithm::ALL.iter().map(|a| a.label()).collect();
            ui.label(format!("GI Studio {}", env!("CARGO_PKG_VERSION")));
            ui.label(algorithms.join(" · "));
        });
        if let Some((path, dirty)) = view.file {
            ui.separator();
            ui.weak(format!("{}{}", path.display(), if dirty { " •" } else { "" }));
        }
    });
}

fn file_menu_ui(ui: &mut egui::Ui, view: &MenuView, commands: &mut Vec<Command>) {
    let mut choose = |ui: &mut egui::Ui, command: Command| {
        commands.push(command);
        ui.close();
    };
    ui.menu_button("New from preset", |ui| {
        for name in presets::names() {
            if ui.button(name).clicked() {
                choose(ui, Command::Request(Action::NewFromPreset(name.to_owned())));
            }
        }
    });
    if ui.button("Open…").clicked() {
        choose(ui, Command::OpenDialog(DialogPurpose::OpenScene));
    }
    if ui.button("Import mesh…").clicked() {
        choose(ui, Command::OpenDialog(DialogPurpose::ImportMesh));
    }
    ui.menu_button("Open recent", |ui| {
        if view.recent.is_empty() {
            ui.weak("Nothing yet");
        }
        for path in view.recent {
            if ui.button(path.display().to_string()).clicked() {
                choose(ui, Command::Request(Action::Open(path.clone())));
            }
        }
    });
    if ui.add(egui::Button::new("Save").shortcut_text("Ctrl+S")).clicked() {
        choose(ui, Command::Save);
    }
    if ui.button("Save as…").clicked() {
        choose(ui, Command::OpenDialog(DialogPurpose::SaveScene));
    }
    ui.menu_button("Export image", |ui| {
        for (pane, &algorithm) in view.panes.iter().enumerate() {
            ui.label(format!("Pane {}: {}", pane + 1, algorithm.label()));
            ui.horizontal(|ui| {
                for (label, exr) in [("PNG (display)…", false), ("EXR (linear)…", true)] {
                    let button = ui.button(label).on_hover_text(format!("Pane {}'s image as {label}", pane + 1));
                    if button.clicked() {
                        choose(ui, Command::OpenDialog(DialogPurpose::ExportImage { pane, algorithm, exr }));
                    }
                }
            });
        }
    });
    if ui.button("Save window screenshot…").clicked() {
        choose(ui, Command::OpenDialog(DialogPurpose::Screenshot));
    }
    if ui.button("Export comparison sheet…").clicked() {
        choose(ui, Command::OpenDialog(DialogPurpose::ComparisonSheet));
    }
    ui.separator();
    if ui.button("Quit").clicked() {
        choose(ui, Command::Request(Action::Quit));
    }
}
