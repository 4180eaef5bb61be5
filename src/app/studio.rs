//! The studio's root: the document, the panes, the dialogs, the capture and
//! the difference view, each its own room. Every frame: take the engine's
//! events, draw (the rooms return commands), apply the commands, and if the
//! scene has a new valid revision, restart every pane with its snapshot.
//! The UI thread never waits on the engine.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui;

use super::capture::ScreenshotRequest;
use super::commands::{Action, Command, Panel};
use super::dialogs::Dialogs;
use super::difference::Difference;
use super::document::Document;
use super::export::export_image;
use super::files::DialogPurpose;
use super::inspector::{inspector_ui, Selection};
use super::menu::{menu_bar_ui, MenuView};
use super::pane::Pane;
use super::panes::{pane_count, Panes};
use super::plots::plots_ui;
use super::storage::{Persisted, StateFile};
use super::StudioArgs;
use crate::render::image::ImageFormat;
use crate::render::LinearImage;
use crate::scene::{load_scene, parse_scene, presets, Scene};

const STATE_KEY: &str = "studio";
const AUTOSAVE_KEY: &str = "autosave_scene";
const STATE_SAVE_INTERVAL: Duration = Duration::from_secs(10);
const RECENT_FILES: usize = 8;

pub struct StudioApp {
    document: Document,
    panes: Panes,
    selection: Selection,
    dialogs: Dialogs,
    screenshot: Option<ScreenshotRequest>,
    difference: Difference,
    show_plots: bool,
    show_difference: bool,
    show_debug: bool,
    recent: Vec<PathBuf>,
    /// The last error to show the user (bad file, failed save…), and news.
    error: Option<String>,
    status: String,
    quit_confirmed: bool,
    /// A `--screenshot` run: it saves no state and never touches the autosave.
    capture_only: bool,
    state_file: Option<StateFile>,
    last_state_save: Instant,
    last_frame: Option<Instant>,
    frame_ms: f32,
    paused: bool,
    ctx: egui::Context,
    exit_error: Arc<Mutex<Option<String>>>,
}

impl StudioApp {
    /// Build the studio; `storage` restores layout, settings and recent
    /// files (checked: a bad saved value falls back with a notice).
    pub fn new(ctx: &egui::Context, storage: Option<&dyn eframe::Storage>, args: &StudioArgs) -> Self {
        let saved: Persisted = storage
            .and_then(|s| s.get_string(STATE_KEY))
            .and_then(|text| ron::from_str(&text).ok())
            .unwrap_or_default();
        let restored = saved.restore();
        let mut error = None;
        let (scene, path) = match &args.scene {
            Some(path) => match load_scene(path) {
                Ok(scene) => (scene.into_scene(), Some(path.clone())),
                Err(e) => {
                    error = Some(e.to_string());
                    (presets::default_scene(), None)
                }
            },
            None => (presets::default_scene(), None),
        };
        let capture_only = args.screenshot.is_some();
        let autosave_offer = (storage.and_then(|s| s.get_string(AUTOSAVE_KEY)))
            .and_then(|text| parse_scene(&text, Path::new("autosave.ron")).ok())
            .map(|valid| valid.into_scene())
            .filter(|s| *s != scene && !capture_only);
        let count = pane_count(args.panes.unwrap_or(restored.panes.len().max(1)));
        let mut app = Self {
            panes: Panes::new(ctx),
            document: Document::new(scene, path, true),
            selection: Selection::Camera,
            dialogs: Dialogs::new(autosave_offer),
            screenshot: None,
            difference: Difference::default(),
            show_plots: restored.show_plots,
            show_difference: false,
            show_debug: false,
            recent: restored.recent,
            error,
            status: restored.notices.join("; "),
            quit_confirmed: false,
            capture_only,
            state_file: None,
            last_state_save: Instant::now(),
            last_frame: None,
            frame_ms: 0.0,
            paused: false,
            ctx: ctx.clone(),
            exit_error: Arc::new(Mutex::new(None)),
        };
        let saved_panes = if args.panes.is_none() { restored.panes } else { Vec::new() };
        app.panes.build(count, &saved_panes, &restored.exposures, &app.document.scene().settings);
        app.restart_all();
        if let Some(path) = &args.screenshot {
            app.screenshot = Some(ScreenshotRequest {
                after_passes: Some(args.quit_after_passes.max(1)),
                quit_after: true,
                delay: 0,
                ..ScreenshotRequest::new(path.clone(), None)
            });
        }
        app
    }

    // ---- What the tests and the binary read and drive ------------------------

    pub fn scene(&self) -> &Scene {
        self.document.scene()
    }

    /// Edit the scene as the inspector does (a new revision).
    pub fn edit_scene(&mut self, edit: impl FnOnce(&mut Scene)) {
        edit(self.document.scene_mut());
        self.document.changed();
    }

    pub fn panes(&self) -> &[Pane] {
        self.panes.list()
    }

    pub fn panes_mut(&mut self) -> &mut [Pane] {
        self.panes.list_mut()
    }

    /// Where each pane's image was drawn last frame (screen points).
    pub fn viewport_rects(&self) -> &[egui::Rect] {
        self.panes.rects()
    }

    pub fn selection(&self) -> Selection {
        self.selection
    }

    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    pub fn status(&self) -> &str {
        &self.status
    }

    /// Whether rendering is paused (the window is minimised).
    pub fn is_paused(&self) -> bool {
        self.paused
    }

    /// Whether the last session's unsaved scene is being offered back.
    pub fn offers_autosave(&self) -> bool {
        self.dialogs.offers_autosave()
    }

    /// The generation each pane is rendering (tests watch restarts with it).
    pub fn generations(&self) -> Vec<u64> {
        self.panes.generations()
    }

    /// The slot where a failed headless screenshot leaves its error.
    pub fn exit_error(&self) -> Arc<Mutex<Option<String>>> {
        self.exit_error.clone()
    }

    /// Keep the state in `file`: written every few seconds and on exit.
    pub fn keep_state_in(&mut self, file: StateFile) {
        self.state_file = Some(file);
    }

    /// Add a line to the status bar.
    pub fn notice(&mut self, message: String) {
        if message.is_empty() {
            return;
        }
        if !self.status.is_empty() {
            self.status += "; ";
        }
        self.status += &message;
    }

    /// Render every pane afresh with the scene as it stands (after their
    /// settings changed).
    pub fn restart_all(&mut self) {
        self.document.check();
        if let Some(scene) = self.document.valid().cloned() {
            self.panes.restart_all(&scene);
        }
        self.load_reference();
    }

    /// Open a scene file; a broken one leaves the scene being edited as it was.
    pub fn open_path(&mut self, path: &Path) {
        match load_scene(path) {
            Ok(scene) => {
                self.replace_scene(scene.into_scene(), Some(path.to_owned()), true);
                self.remember(path);
                self.error = None;
                self.status = format!("Opened {}", path.display());
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Save pane `index`'s current image (.png tone-mapped, .exr linear).
    pub fn export_pane(&mut self, index: usize, path: &Path) {
        let Some(pane) = self.panes.list().get(index) else { return };
        match export_image(&pane.state().image, pane.exposure(), path) {
            Ok(()) => self.status = format!("Exported {}", path.display()),
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    // ---- Commands ------------------------------------------------------------

    fn apply(&mut self, command: Command) {
        match command {
            Command::Request(action) if self.document.is_dirty() => self.dialogs.ask_unsaved(action),
            Command::Request(action) | Command::Perform(action) => self.perform(action),
            Command::OpenDialog(purpose) => self.open_dialog(purpose),
            Command::Save => self.save_or_ask(),
            Command::SaveThen(action) => {
                self.save_or_ask();
                if !self.document.is_dirty() {
                    self.perform(action);
                }
            }
            Command::Write(purpose, path) => self.write_chosen(purpose, path),
            Command::Undo => self.document.undo(),
            Command::Redo => self.document.redo(),
            Command::SetPanes(count) if count != self.panes.count() => {
                self.panes.build(pane_count(count), &[], &[], &self.document.scene().settings);
                self.restart_all();
            }
            Command::SetPanes(_) => {}
            Command::Show(Panel::Plots, on) => self.show_plots = on,
            Command::Show(Panel::Difference, on) => self.show_difference = on,
            Command::Show(Panel::Debug, on) => self.show_debug = on,
            Command::RestoreAutosave => {
                if let Some(scene) = self.dialogs.take_autosave() {
                    // Restored, not saved: it stays an unsaved edit until saved
                    self.replace_scene(scene, None, false);
                }
            }
            Command::DiscardAutosave => drop(self.dialogs.take_autosave()),
        }
    }

    fn perform(&mut self, action: Action) {
        match action {
            Action::NewFromPreset(name) => match presets::preset(&name) {
                Some(Ok(scene)) => {
                    self.replace_scene(scene.into_scene(), None, true);
                    self.status = format!("New scene from the {name} preset");
                }
                Some(Err(e)) => self.error = Some(e.to_string()),
                None => self.error = Some(format!("no preset called {name}")),
            },
            Action::Open(path) => self.open_path(&path),
            Action::Quit => {
                self.quit_confirmed = true;
                self.ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
    }

    fn replace_scene(&mut self, scene: Scene, path: Option<PathBuf>, clean: bool) {
        self.document = Document::new(scene, path, clean);
        self.selection = Selection::Camera;
        self.panes.rebuild_for(&self.document.scene().settings);
        self.restart_all();
    }

    fn remember(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_owned());
        self.recent.truncate(RECENT_FILES);
    }

    fn save_or_ask(&mut self) {
        match self.document.path().map(Path::to_owned) {
            Some(path) => self.save_to(&path),
            None => self.open_dialog(DialogPurpose::SaveScene),
        }
    }

    fn save_to(&mut self, path: &Path) {
        match self.document.save_to(path) {
            Ok(()) => {
                self.remember(path);
                self.status = format!("Saved {}", path.display());
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn open_dialog(&mut self, purpose: DialogPurpose) {
        let suggestion = match purpose {
            DialogPurpose::OpenScene | DialogPurpose::SaveScene => {
                self.document.path().map_or_else(|| PathBuf::from("assets/scenes/untitled.ron"), Path::to_owned)
            }
            DialogPurpose::ExportPng => PathBuf::from("render.png"),
            DialogPurpose::ExportExr => PathBuf::from("render.exr"),
            DialogPurpose::Screenshot => PathBuf::from("screenshot.png"),
            DialogPurpose::ComparisonSheet => PathBuf::from("comparison.png"),
        };
        self.dialogs.open_file(purpose, &suggestion);
    }

    /// Act on a path the file dialog chose.
    fn write_chosen(&mut self, purpose: DialogPurpose, path: PathBuf) {
        match purpose {
            DialogPurpose::OpenScene => self.apply(Command::Request(Action::Open(path))),
            DialogPurpose::SaveScene => self.save_to(&path),
            DialogPurpose::ExportPng | DialogPurpose::ExportExr => self.export_pane(0, &path),
            DialogPurpose::Screenshot => self.take_screenshot(path, None),
            DialogPurpose::ComparisonSheet => self.take_screenshot(path, Some(self.panes.area())),
        }
    }

    /// Save the window (or, for the comparison sheet, the panes' area with
    /// their labels) as PNG at the next frame.
    fn take_screenshot(&mut self, path: PathBuf, crop: Option<egui::Rect>) {
        if !matches!(ImageFormat::of(&path), Ok(ImageFormat::Png)) {
            self.error = Some(format!("{}: screenshots are PNG files (end the name in .png)", path.display()));
            return;
        }
        self.screenshot = Some(ScreenshotRequest::new(path, crop));
    }

    /// The preset's stored reference, used for the panes' error when their
    /// size is a whole multiple of it.
    fn load_reference(&mut self) {
        let scene = self.document.scene();
        let name = presets::names().find(|n| presets::preset(n).and_then(Result::ok).is_some_and(|s| *s == *scene));
        let reference =
            name.and_then(|name| LinearImage::load(Path::new(&format!("assets/references/{name}.exr"))).ok());
        self.panes.set_reference(reference);
    }

    // ---- The frame -----------------------------------------------------------

    fn input_commands(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        let shortcut = |modifiers, key| ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(modifiers, key)));
        if shortcut(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z) {
            commands.push(Command::Redo);
        } else if shortcut(Modifiers::COMMAND, Key::Z) {
            commands.push(Command::Undo);
        }
        if shortcut(Modifiers::COMMAND, Key::S) {
            commands.push(Command::Save);
        }
        if shortcut(Modifiers::COMMAND, Key::O) {
            commands.push(Command::OpenDialog(DialogPurpose::OpenScene));
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_owned()).collect());
        if let Some(path) = dropped.into_iter().find(|p| p.extension().is_some_and(|e| e == "ron")) {
            commands.push(Command::Request(Action::Open(path)));
        }
        if ctx.input(|i| i.viewport().close_requested()) && self.document.is_dirty() && !self.quit_confirmed {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.dialogs.ask_unsaved(Action::Quit);
        }
        // Rendering pauses while the window is minimised
        let minimised = ctx.input(|i| i.viewport().minimized).unwrap_or(false);
        if minimised && !self.paused {
            self.panes.pause_all();
            self.paused = true;
        } else if !minimised && self.paused {
            self.paused = false;
            self.restart_all();
        }
    }

    /// One frame of the whole studio.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.frame_ms = 0.9 * self.frame_ms + 0.1 * (now - last).as_secs_f32() * 1e3;
        }
        self.last_frame = Some(now);
        self.panes.poll();
        let mut commands = Vec::new();
        self.input_commands(&ctx, &mut commands);

        egui::Panel::top("menu").show(ui, |ui| {
            let view = MenuView {
                can_undo: self.document.can_undo(),
                can_redo: self.document.can_redo(),
                recent: &self.recent,
                panes: self.panes.count(),
                plots: self.show_plots,
                difference: self.show_difference,
                debug: self.show_debug,
                file: self.document.path().map(|p| (p, self.document.is_dirty())),
            };
            menu_bar_ui(ui, &view, &mut commands);
        });
        self.status_ui(ui);
        egui::Panel::left("inspector").resizable(true).default_size(330.0).show(ui, |ui| {
            let problems = self.document.problems().to_vec();
            if inspector_ui(ui, self.document.scene_mut(), &mut self.selection, &problems) {
                self.document.changed();
            }
        });
        if self.show_plots {
            egui::Panel::bottom("plots")
                .resizable(true)
                .default_size(200.0)
                .show(ui, |ui| plots_ui(ui, self.panes.list()));
        }
        egui::CentralPanel::default().show(ui, |ui| self.panes.panes_ui(ui, &mut self.document, &mut self.selection));
        self.dialogs.dialogs_ui(&ctx, self.document.path(), &mut commands);
        if self.show_difference {
            self.difference.difference_ui(&ctx, &self.panes);
        }
        for command in commands {
            self.apply(command);
        }

        self.document.commit(ctx.input(|i| i.pointer.any_down()));
        if let Some(scene) = self.document.check() {
            if !self.paused {
                self.panes.restart_all(&scene);
                self.load_reference();
            }
        }
        self.capture_step(&ctx);
        if self.last_state_save.elapsed() >= STATE_SAVE_INTERVAL {
            if let Err(e) = self.save_state() {
                self.error = Some(e);
            }
        }
        if self.show_debug {
            self.debug_ui(&ctx);
        }
    }

    fn status_ui(&mut self, ui: &mut egui::Ui) {
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| match &self.error {
                Some(error) => {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                    if ui.small_button("Dismiss").clicked() {
                        self.error = None;
                    }
                }
                None => {
                    ui.label(&self.status);
                }
            });
        });
    }

    fn debug_ui(&self, ctx: &egui::Context) {
        let area = egui::Area::new(egui::Id::unique("debug")).anchor(egui::Align2::RIGHT_TOP, egui::vec2(-8.0, 28.0));
        area.show(ctx, |ui| {
            let text = egui::RichText::new(format!("UI frame {:.1} ms", self.frame_ms)).monospace();
            ui.label(text.background_color(egui::Color32::from_black_alpha(180)));
        });
        ctx.request_repaint();
    }

    fn capture_step(&mut self, ctx: &egui::Context) {
        let Some(shot) = &mut self.screenshot else { return };
        let ready = shot.after_passes.is_none_or(|n| self.panes.all_have(n));
        let Some(outcome) = shot.step(ctx, ready) else { return };
        let quit = shot.quit_after;
        self.screenshot = None;
        match outcome {
            Ok(path) => self.status = format!("Saved {}", path.display()),
            Err(e) => {
                self.error = Some(e.clone());
                if let Ok(mut slot) = self.exit_error.lock() {
                    *slot = Some(e);
                }
            }
        }
        if quit {
            self.quit_confirmed = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    // ---- What survives a restart ---------------------------------------------

    pub fn persisted(&self) -> Persisted {
        let panes = self.panes.list();
        Persisted {
            panes: panes.iter().map(|p| p.settings().clone()).collect(),
            exposures: panes.iter().map(Pane::exposure).collect(),
            show_plots: self.show_plots,
            recent: self.recent.clone(),
        }
    }

    /// Write the state file (layout and autosave) if there is one.
    fn save_state(&mut self) -> Result<(), String> {
        self.last_state_save = Instant::now();
        let Some(mut file) = self.state_file.take() else { return Ok(()) };
        eframe::App::save(self, &mut file);
        let written = if self.capture_only { Ok(()) } else { file.write() };
        self.state_file = Some(file);
        written.map_err(|e| format!("could not save the studio's state: {e}"))
    }
}

impl eframe::App for StudioApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }

    /// The layout and the autosave. A `--screenshot` run writes neither; while
    /// the last session's scene is offered back, its autosave stays as it is
    /// (a second crash must not lose it).
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.capture_only {
            return;
        }
        match ron::to_string(&self.persisted()) {
            Ok(text) => storage.set_string(STATE_KEY, text),
            Err(e) => self.error = Some(format!("could not save the studio's layout: {e}")),
        }
        if self.dialogs.offers_autosave() {
            return;
        }
        match self.document.autosave_text() {
            None => storage.set_string(AUTOSAVE_KEY, String::new()),
            Some(Ok(text)) => storage.set_string(AUTOSAVE_KEY, text),
            Some(Err(e)) => self.error = Some(format!("could not autosave the scene: {e}")),
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        // The window is gone: the terminal is the one place left to say it
        if let Err(e) = self.save_state() {
            eprintln!("error: {e}");
        }
    }
}
