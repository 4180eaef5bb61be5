//! The menu bar: File, Edit, View, Help.

use eframe::egui;

use super::files::DialogPurpose;
use super::studio::{Action, StudioApp};
use crate::scene::presets;

pub fn menu_bar_ui(ui: &mut egui::Ui, app: &mut StudioApp) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            ui.menu_button("New from preset", |ui| {
                for name in presets::names() {
                    if ui.button(name).clicked() {
                        app.request(Action::NewFromPreset(name.to_owned()));
                        ui.close();
                    }
                }
            });
            if ui.button("Open…").clicked() {
                app.open_dialog(DialogPurpose::OpenScene);
                ui.close();
            }
            ui.menu_button("Open recent", |ui| {
                if app.recent.is_empty() {
                    ui.weak("Nothing yet");
                }
                for path in app.recent.clone() {
                    if ui.button(path.display().to_string()).clicked() {
                        app.request(Action::Open(path));
                        ui.close();
                    }
                }
            });
            if ui.add(egui::Button::new("Save").shortcut_text("Ctrl+S")).clicked() {
                app.save_or_ask();
                ui.close();
            }
            if ui.button("Save as…").clicked() {
                app.open_dialog(DialogPurpose::SaveScene);
                ui.close();
            }
            ui.menu_button("Export image", |ui| {
                if ui.button("PNG (display)…").clicked() {
                    app.open_dialog(DialogPurpose::ExportPng);
                    ui.close();
                }
                if ui.button("EXR (linear)…").clicked() {
                    app.open_dialog(DialogPurpose::ExportExr);
                    ui.close();
                }
            });
            if ui.button("Save window screenshot…").clicked() {
                app.open_dialog(DialogPurpose::Screenshot);
                ui.close();
            }
            if ui.button("Export comparison sheet…").clicked() {
                app.open_dialog(DialogPurpose::ComparisonSheet);
                ui.close();
            }
            ui.separator();
            if ui.button("Quit").clicked() {
                app.request(Action::Quit);
                ui.close();
            }
        });
        ui.menu_button("Edit", |ui| {
            if ui.add_enabled(app.can_undo(), egui::Button::new("Undo").shortcut_text("Ctrl+Z")).clicked() {
                app.undo();
                ui.close();
            }
            if ui.add_enabled(app.can_redo(), egui::Button::new("Redo").shortcut_text("Ctrl+Shift+Z")).clicked() {
                app.redo();
                ui.close();
            }
        });
        ui.menu_button("View", |ui| {
            for count in [1, 2, 4] {
                if ui
                    .radio(app.pane_count() == count, format!("{count} pane{}", if count == 1 { "" } else { "s" }))
                    .clicked()
                {
                    app.set_pane_count(count);
                    ui.close();
                }
            }
            ui.separator();
            ui.checkbox(&mut app.show_plots, "Plots");
            ui.checkbox(&mut app.show_difference, "Difference view");
            ui.checkbox(&mut app.show_debug, "Debug overlay (frame time)");
        });
        ui.menu_button("Help", |ui| {
            ui.label("Drag: orbit · Shift+drag: pan · Scroll: dolly · Click: select");
            ui.label("Ctrl+Z / Ctrl+Shift+Z: undo / redo · Ctrl+S: save · Ctrl+O: open");
            ui.label("Drop a .ron file on the window to open it.");
            ui.separator();
            ui.label(format!("GI Studio {} — Whitted, path tracing, photon mapping, SPPM", env!("CARGO_PKG_VERSION")));
        });
        if let Some(path) = &app.scene_path {
            ui.separator();
            let mark = if app.is_dirty() { " •" } else { "" };
            ui.weak(format!("{}{mark}", path.display()));
        }
    });
}
