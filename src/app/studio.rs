//! The studio: one scene being edited, up to four panes rendering it, the
//! inspector, plots and dialogs. Every frame: take the engine's events,
//! draw, and if the scene changed and is valid, restart every pane with a
//! new snapshot. The UI thread never waits on the engine.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use eframe::egui;
use serde::{Deserialize, Serialize};

use super::capture::{save_screenshot, ScreenshotRequest};
use super::export::{difference_rgba, export_image};
use super::files::{file_dialog_ui, DialogPurpose, FileDialog};
use super::history::History;
use super::inspector::{inspector_ui, Selection};
use super::menu::menu_bar_ui;
use super::pane::Pane;
use super::plots::plots_ui;
use super::storage::StateFile;
use super::viewport::viewport_ui;
use super::StudioArgs;
use crate::limits;
use crate::render::image::ImageFormat;
use crate::render::{Algorithm, LinearImage, Method, RenderSettings};
use crate::scene::{load_scene, presets, save_scene, to_ron, Invalid, Scene};

/// What survives a restart (eframe storage).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default)]
pub struct Persisted {
    pub panes: Vec<RenderSettings>,
    pub exposures: Vec<f32>,
    pub show_plots: bool,
    pub recent: Vec<PathBuf>,
}

impl Default for Persisted {
    fn default() -> Self {
        Self { panes: Vec::new(), exposures: Vec::new(), show_plots: true, recent: Vec::new() }
    }
}

/// Saved state made safe to start from: a pane whose saved settings break
/// a limit gets its defaults (`None`), and every fallback is said.
pub struct Restored {
    pub panes: Vec<Option<RenderSettings>>,
    pub exposures: Vec<f32>,
    pub show_plots: bool,
    pub recent: Vec<PathBuf>,
    pub notices: Vec<String>,
}

impl Persisted {
    /// The saved state checked as a scene file is: whatever it holds, the
    /// studio starts, and values out of their limits fall back to defaults.
    pub fn restore(self) -> Restored {
        let mut notices = Vec::new();
        if self.panes.len() > 4 {
            notices.push(format!("{} saved panes; the studio shows at most 4", self.panes.len()));
        }
        let panes = (self.panes.into_iter().take(4).enumerate())
            .map(|(i, settings)| match settings.problems().first() {
                None => Some(settings),
                Some(problem) => {
                    notices.push(format!("pane {}'s saved {problem}; its defaults are used", i + 1));
                    None
                }
            })
            .collect();
        let exposures = (self.exposures.into_iter().take(4).enumerate())
            .map(|(i, exposure)| {
                limits::EXPOSURE_STOPS.check(exposure).unwrap_or_else(|problem| {
                    notices.push(format!("pane {}'s saved exposure {problem}; 0 is used", i + 1));
                    0.0
                })
            })
            .collect();
        let recent = self.recent.into_iter().take(RECENT_FILES).collect();
        Restored { panes, exposures, show_plots: self.show_plots, recent, notices }
    }
}

const RECENT_FILES: usize = 8;

const STATE_KEY: &str = "studio";
const STATE_SAVE_INTERVAL: std::time::Duration = std::time::Duration::from_secs(10);
const AUTOSAVE_KEY: &str = "autosave_scene";

/// Something that would discard unsaved edits: asked about first.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    NewFromPreset(String),
    Open(PathBuf),
    Quit,
}

pub struct StudioApp {
    pub scene: Scene,
    pub scene_path: Option<PathBuf>,
    saved: Scene,
    rendered: Option<Scene>,
    pub panes: Vec<Pane>,
    pub selection: Selection,
    history: History,
    pub problems: Vec<Invalid>,
    /// The last error to show the user (bad file, failed save…).
    pub error: Option<String>,
    pub status: String,
    pub show_plots: bool,
    pub show_difference: bool,
    pub show_debug: bool,
    pub recent: Vec<PathBuf>,
    pub panes_rect: egui::Rect,
    /// Where each pane's image was drawn last frame (screen points).
    pub viewport_rects: Vec<egui::Rect>,
    dialog: Option<FileDialog>,
    /// A chosen path that exists, waiting for the user to say replace it.
    replace: Option<(DialogPurpose, PathBuf)>,
    pending: Option<Action>,
    quit_confirmed: bool,
    /// The last session's unsaved scene, offered back; until answered, the
    /// autosave that holds it is left alone.
    autosave_offer: Option<Scene>,
    /// A `--screenshot` run: it saves no state and never touches the autosave.
    capture_only: bool,
    state_file: Option<StateFile>,
    last_state_save: Instant,
    screenshot: Option<ScreenshotRequest>,
    difference: Option<egui::TextureHandle>,
    difference_at: Option<Instant>,
    reference: Option<LinearImage>,
    last_frame: Option<Instant>,
    frame_ms: f32,
    paused: bool,
    ctx: egui::Context,
    pub exit_error: Arc<Mutex<Option<String>>>,
}

fn default_algorithms(count: usize) -> Vec<Algorithm> {
    match count {
        1 => vec![Algorithm::Path],
        2 => vec![Algorithm::Path, Algorithm::Whitted],
        _ => Algorithm::ALL.to_vec(),
    }
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
        let autosaved = storage.and_then(|s| s.get_string(AUTOSAVE_KEY)).filter(|t| !t.is_empty());
        let mut error = None;
        let (scene, scene_path) = match &args.scene {
            Some(path) => match load_scene(path) {
                Ok(scene) => (scene, Some(path.clone())),
                Err(e) => {
                    error = Some(e.to_string());
                    (presets::default_scene(), None)
                }
            },
            None => (presets::default_scene(), None),
        };
        let capture_only = args.screenshot.is_some();
        let autosave_offer = autosaved
            .and_then(|text| crate::scene::parse_scene(&text, Path::new("autosave.ron")).ok())
            .filter(|s| *s != scene && !capture_only);
        let count = args.panes.unwrap_or(restored.panes.len().max(1)).clamp(1, 4);
        let count = if count == 3 { 4 } else { count };
        let mut app = Self {
            saved: scene.clone(),
            history: History::new(&scene),
            scene,
            scene_path,
            rendered: None,
            panes: Vec::new(),
            selection: Selection::Camera,
            problems: Vec::new(),
            error,
            status: restored.notices.join("; "),
            show_plots: restored.show_plots,
            show_difference: false,
            show_debug: false,
            recent: restored.recent,
            panes_rect: egui::Rect::NOTHING,
            viewport_rects: Vec::new(),
            dialog: None,
            replace: None,
            pending: None,
            quit_confirmed: false,
            autosave_offer,
            capture_only,
            state_file: None,
            last_state_save: Instant::now(),
            screenshot: None,
            difference: None,
            difference_at: None,
            reference: None,
            last_frame: None,
            frame_ms: 0.0,
            paused: false,
            ctx: ctx.clone(),
            exit_error: Arc::new(Mutex::new(None)),
        };
        let saved_panes = if args.panes.is_none() { restored.panes } else { Vec::new() };
        app.build_panes(count, &saved_panes, &restored.exposures);
        if let Some(path) = &args.screenshot {
            app.screenshot = Some(ScreenshotRequest {
                after_passes: Some(args.quit_after_passes.max(1)),
                quit_after: true,
                delay: 0,
                ..ScreenshotRequest::new(path.clone(), None)
            });
        }
        app.load_reference();
        app
    }

    /// Keep the state in `file`: written every few seconds and on exit.
    pub fn keep_state_in(&mut self, file: StateFile) {
        self.state_file = Some(file);
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

    fn pane_settings(&self, algorithm: Algorithm, count: usize) -> RenderSettings {
        // Four panes share the cores: each renders at half size
        let divisor = if count >= 4 { 2 } else { 1 };
        RenderSettings {
            width: (self.scene.settings.width / divisor).max(16),
            height: (self.scene.settings.height / divisor).max(16),
            samples_per_pixel: Some(4096),
            preview: true,
            ..RenderSettings::for_algorithm(algorithm)
        }
    }

    fn build_panes(&mut self, count: usize, saved: &[Option<RenderSettings>], exposures: &[f32]) {
        let algorithms = default_algorithms(count);
        self.panes = (0..count)
            .map(|i| {
                let settings =
                    saved.get(i).cloned().flatten().unwrap_or_else(|| self.pane_settings(algorithms[i], count));
                let mut pane = Pane::new(&self.ctx, settings);
                pane.exposure = exposures.get(i).copied().unwrap_or(self.scene.settings.exposure);
                pane
            })
            .collect();
        self.rendered = None;
    }

    pub fn pane_count(&self) -> usize {
        self.panes.len()
    }

    pub fn set_pane_count(&mut self, count: usize) {
        if count != self.panes.len() {
            self.build_panes(count, &[], &[]);
            self.load_reference();
        }
    }

    pub fn is_dirty(&self) -> bool {
        self.scene != self.saved
    }

    pub fn can_undo(&self) -> bool {
        self.history.can_undo()
    }

    pub fn can_redo(&self) -> bool {
        self.history.can_redo()
    }

    pub fn undo(&mut self) {
        self.history.undo(&mut self.scene);
    }

    pub fn redo(&mut self) {
        self.history.redo(&mut self.scene);
    }

    /// Whether rendering is paused (the window is minimised).
    pub fn is_paused(&self) -> bool {
        self.paused
    }

    /// Whether the last session's unsaved scene is being offered back.
    pub fn offers_autosave(&self) -> bool {
        self.autosave_offer.is_some()
    }

    /// The generation each pane is rendering (tests watch restarts with it).
    pub fn generations(&self) -> Vec<u64> {
        self.panes.iter().map(|p| p.state.generation).collect()
    }

    /// Do `action` now, or ask first if it would discard unsaved edits.
    pub fn request(&mut self, action: Action) {
        if self.is_dirty() {
            self.pending = Some(action);
        } else {
            self.perform(action);
        }
    }

    fn perform(&mut self, action: Action) {
        match action {
            Action::NewFromPreset(name) => match presets::preset(&name) {
                Some(Ok(scene)) => {
                    self.replace_scene(scene, None);
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

    fn replace_scene(&mut self, scene: Scene, path: Option<PathBuf>) {
        self.history = History::new(&scene);
        self.saved = scene.clone();
        self.scene = scene;
        self.scene_path = path;
        self.selection = Selection::Camera;
        let count = self.panes.len();
        let saved: Vec<RenderSettings> = self.panes.iter().map(|p| p.settings.clone()).collect();
        // The new scene's image size applies to every pane
        let resized: Vec<Option<RenderSettings>> = saved
            .into_iter()
            .map(|s| {
                Some(RenderSettings {
                    width: self.pane_settings(s.algorithm(), count).width,
                    height: self.pane_settings(s.algorithm(), count).height,
                    ..s
                })
            })
            .collect();
        let exposures: Vec<f32> = vec![self.scene.settings.exposure; count];
        self.build_panes(count, &resized, &exposures);
        self.load_reference();
    }

    /// Open a scene file; a broken one leaves the scene being edited as it was.
    pub fn open_path(&mut self, path: &Path) {
        match load_scene(path) {
            Ok(scene) => {
                self.replace_scene(scene, Some(path.to_owned()));
                self.remember(path);
                self.error = None;
                self.status = format!("Opened {}", path.display());
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn remember(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
        self.recent.insert(0, path.to_owned());
        self.recent.truncate(8);
    }

    pub fn save_or_ask(&mut self) {
        match self.scene_path.clone() {
            Some(path) => self.save_to(&path),
            None => self.open_dialog(DialogPurpose::SaveScene),
        }
    }

    pub fn save_to(&mut self, path: &Path) {
        match save_scene(&self.scene, path) {
            Ok(()) => {
                self.saved = self.scene.clone();
                self.scene_path = Some(path.to_owned());
                self.remember(path);
                self.status = format!("Saved {}", path.display());
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Save pane `index`'s current image (.png tone-mapped, .exr linear).
    pub fn export_pane(&mut self, index: usize, path: &Path) {
        let Some(pane) = self.panes.get(index) else { return };
        match export_image(&pane.state.image, pane.exposure, path) {
            Ok(()) => self.status = format!("Exported {}", path.display()),
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    pub fn open_dialog(&mut self, purpose: DialogPurpose) {
        let suggestion = match purpose {
            DialogPurpose::OpenScene | DialogPurpose::SaveScene => {
                self.scene_path.clone().unwrap_or_else(|| PathBuf::from("assets/scenes/untitled.ron"))
            }
            DialogPurpose::ExportPng => PathBuf::from("render.png"),
            DialogPurpose::ExportExr => PathBuf::from("render.exr"),
            DialogPurpose::Screenshot => PathBuf::from("screenshot.png"),
            DialogPurpose::ComparisonSheet => PathBuf::from("comparison.png"),
        };
        self.dialog = Some(FileDialog::new(purpose, &suggestion));
    }

    /// Save the window (or, for the comparison sheet, the panes' area with
    /// their labels) as PNG at the next frame.
    pub fn take_screenshot(&mut self, path: PathBuf, crop: Option<egui::Rect>) {
        if !matches!(ImageFormat::of(&path), Ok(ImageFormat::Png)) {
            self.error = Some(format!("{}: screenshots are PNG files (end the name in .png)", path.display()));
            return;
        }
        self.screenshot = Some(ScreenshotRequest::new(path, crop));
    }

    /// The preset's stored reference, used for the panes' error when their
    /// size is a whole multiple of it.
    fn load_reference(&mut self) {
        self.reference = None;
        let Some(name) =
            presets::names().find(|n| presets::preset(n).and_then(Result::ok).is_some_and(|s| s == self.scene))
        else {
            return;
        };
        let path = PathBuf::from(format!("assets/references/{name}.exr"));
        self.reference = LinearImage::load(&path).ok();
    }

    /// Render every pane afresh at the next frame (after settings changed).
    pub fn restart_all(&mut self) {
        self.rendered = None;
    }

    /// Restart every pane if the scene changed and is valid; invalid scenes
    /// are only flagged.
    pub fn sync_engine(&mut self) {
        self.problems = self.scene.validate();
        if !self.problems.is_empty() || self.paused || self.rendered.as_ref() == Some(&self.scene) {
            return;
        }
        let snapshot = Arc::new(self.scene.clone());
        for pane in &mut self.panes {
            pane.restart(snapshot.clone());
        }
        self.rendered = Some(self.scene.clone());
    }

    pub fn poll(&mut self) {
        let reference = &self.reference;
        for pane in &mut self.panes {
            let matching =
                reference.as_ref().filter(|r| r.width == pane.settings.width && r.height == pane.settings.height);
            pane.poll(matching);
        }
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        let redo = ctx
            .input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z)));
        let undo = ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::Z)));
        let save = ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::S)));
        let open = ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::O)));
        if redo {
            self.redo();
        } else if undo {
            self.undo();
        }
        if save {
            self.save_or_ask();
        }
        if open {
            self.open_dialog(DialogPurpose::OpenScene);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_owned()).collect());
        if let Some(path) = dropped.into_iter().find(|p| p.extension().is_some_and(|e| e == "ron")) {
            self.request(Action::Open(path));
        }
        if ctx.input(|i| i.viewport().close_requested()) && self.is_dirty() && !self.quit_confirmed {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.pending = Some(Action::Quit);
        }
        // Rendering pauses while the window is minimised
        let minimised = ctx.input(|i| i.viewport().minimized).unwrap_or(false);
        if minimised && !self.paused {
            self.panes.iter_mut().for_each(Pane::pause);
            self.paused = true;
        } else if !minimised && self.paused {
            self.paused = false;
            self.rendered = None;
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
        self.poll();
        self.handle_input(&ctx);

        egui::Panel::top("menu").show(ui, |ui| menu_bar_ui(ui, self));
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| {
                if let Some(error) = &self.error {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                    if ui.small_button("Dismiss").clicked() {
                        self.error = None;
                    }
                } else {
                    ui.label(&self.status);
                }
            });
        });
        egui::Panel::left("inspector").resizable(true).default_size(330.0).show(ui, |ui| {
            inspector_ui(ui, &mut self.scene, &mut self.selection, &self.problems);
        });
        if self.show_plots {
            egui::Panel::bottom("plots").resizable(true).default_size(200.0).show(ui, |ui| plots_ui(ui, &self.panes));
        }
        egui::CentralPanel::default().show(ui, |ui| {
            self.panes_rect = ui.max_rect();
            self.panes_ui(ui);
        });
        self.windows_ui(&ctx);

        let interacting = ctx.input(|i| i.pointer.any_down());
        self.history.observe(&self.scene, interacting);
        self.sync_engine();
        self.screenshot_step(&ctx);
        if self.last_state_save.elapsed() >= STATE_SAVE_INTERVAL {
            if let Err(e) = self.save_state() {
                self.error = Some(e);
            }
        }
        if self.show_debug {
            egui::Area::new(egui::Id::unique("debug")).anchor(egui::Align2::RIGHT_TOP, egui::vec2(-8.0, 28.0)).show(
                &ctx,
                |ui| {
                    ui.label(
                        egui::RichText::new(format!("UI frame {:.1} ms", self.frame_ms))
                            .monospace()
                            .background_color(egui::Color32::from_black_alpha(180)),
                    );
                },
            );
            ctx.request_repaint();
        }
    }

    fn panes_ui(&mut self, ui: &mut egui::Ui) {
        let count = self.panes.len();
        let columns = if count == 1 { 1 } else { 2 };
        let rows = count.div_ceil(columns);
        let cell = egui::vec2(ui.available_width() / columns as f32, ui.available_height() / rows as f32);
        let origin = ui.min_rect().min;
        for index in 0..count {
            let (row, column) = (index / columns, index % columns);
            let min = origin + egui::vec2(column as f32 * cell.x, row as f32 * cell.y);
            let rect = egui::Rect::from_min_size(min, cell).shrink(3.0);
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect).id_salt(("pane", index)));
            self.pane_ui(&mut child, index);
        }
    }

    fn pane_ui(&mut self, ui: &mut egui::Ui, index: usize) {
        let mut restart = false;
        ui.horizontal(|ui| {
            let pane = &mut self.panes[index];
            let mut algorithm = pane.settings.algorithm();
            egui::ComboBox::new(("algorithm", index), format!("pane {}", index + 1))
                .selected_text(algorithm.label())
                .show_ui(ui, |ui| {
                    for a in Algorithm::ALL {
                        ui.selectable_value(&mut algorithm, a, a.label());
                    }
                });
            if algorithm != pane.settings.algorithm() {
                pane.settings.method = Method::of(algorithm);
                pane.settings.max_depth = algorithm.default_max_depth();
                restart = true;
            }
            ui.menu_button("Settings", |ui| restart |= pane_settings_ui(ui, pane));
            if ui.small_button("Restart").on_hover_text("Restart this pane").clicked() {
                restart = true;
            }
        });
        if restart && self.problems.is_empty() {
            self.panes[index].restart(Arc::new(self.scene.clone()));
        }
        let pane = &mut self.panes[index];
        let rect = viewport_ui(ui, pane, &mut self.scene, &mut self.selection).rect;
        self.viewport_rects.resize(self.panes.len(), egui::Rect::NOTHING);
        self.viewport_rects[index] = rect;
    }

    fn windows_ui(&mut self, ctx: &egui::Context) {
        if let Some(dialog) = &mut self.dialog {
            let (chosen, open) = file_dialog_ui(ctx, dialog);
            let purpose = dialog.purpose;
            if !open {
                self.dialog = None;
            }
            if let Some(path) = chosen {
                // Writing over another file is the user's call, asked once
                let own_file = purpose == DialogPurpose::SaveScene && self.scene_path.as_deref() == Some(&path);
                if purpose != DialogPurpose::OpenScene && path.exists() && !own_file {
                    self.replace = Some((purpose, path));
                } else {
                    self.write_chosen(purpose, path);
                }
            }
        }
        if let Some((purpose, path)) = self.replace.clone() {
            egui::Window::new("Replace file?").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label(format!("{} already exists. Replace it?", path.display()));
                ui.horizontal(|ui| {
                    if ui.button("Replace").clicked() {
                        self.replace = None;
                        self.write_chosen(purpose, path.clone());
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
                        self.save_or_ask();
                        self.pending = None;
                        if !self.is_dirty() {
                            self.perform(action.clone());
                        }
                    }
                    if ui.button("Discard").clicked() {
                        self.pending = None;
                        self.perform(action.clone());
                    }
                    if ui.button("Cancel").clicked() {
                        self.pending = None;
                    }
                });
            });
        }
        if let Some(scene) = self.autosave_offer.clone() {
            egui::Window::new("Restore unsaved scene?").collapsible(false).resizable(false).show(ctx, |ui| {
                ui.label("The last session ended with unsaved edits. Restore that scene?");
                ui.horizontal(|ui| {
                    if ui.button("Restore").clicked() {
                        self.replace_scene(scene.clone(), None);
                        self.saved = presets::default_scene();
                        self.autosave_offer = None;
                    }
                    if ui.button("Discard").clicked() {
                        self.autosave_offer = None;
                    }
                });
            });
        }
        if self.show_difference {
            self.difference_ui(ctx);
        }
    }

    /// Act on a path the file dialog chose (and, if it existed, the user
    /// agreed to replace).
    pub fn write_chosen(&mut self, purpose: DialogPurpose, path: PathBuf) {
        match purpose {
            DialogPurpose::OpenScene => self.request(Action::Open(path)),
            DialogPurpose::SaveScene => self.save_to(&path),
            DialogPurpose::ExportPng | DialogPurpose::ExportExr => self.export_pane(0, &path),
            DialogPurpose::Screenshot => self.take_screenshot(path, None),
            DialogPurpose::ComparisonSheet => self.take_screenshot(path, Some(self.panes_rect)),
        }
    }

    fn difference_ui(&mut self, ctx: &egui::Context) {
        let refresh = self.difference_at.is_none_or(|t| t.elapsed().as_secs_f32() > 0.5);
        let mut caption = "Needs two panes of the same size".to_owned();
        if self.panes.len() >= 2 {
            let (a, b) = (&self.panes[0].state.image, &self.panes[1].state.image);
            let against = self.reference.as_ref().filter(|r| r.width == a.width && r.height == a.height).unwrap_or(b);
            let label = if std::ptr::eq(against, b) { "pane 1 against pane 2" } else { "pane 1 against the reference" };
            if refresh {
                if let Some((rgba, top)) = difference_rgba(a, against) {
                    let image = egui::ColorImage::from_rgba_unmultiplied([a.width as usize, a.height as usize], &rgba);
                    self.difference = Some(ctx.load_texture("difference", image, egui::TextureOptions::NEAREST));
                    self.difference_at = Some(Instant::now());
                    caption = format!("relative error, {label}; white = {top:.2e}");
                }
            } else {
                caption = format!("relative error, {label}");
            }
        }
        egui::Window::new("Difference").default_size([360.0, 300.0]).show(ctx, |ui| {
            ui.label(&caption);
            if let Some(texture) = &self.difference {
                let size = texture.size_vec2();
                let scale = (ui.available_width() / size.x).min(2.0);
                ui.image((texture.id(), size * scale));
            }
        });
        ctx.request_repaint_after(std::time::Duration::from_millis(500));
    }

    fn screenshot_step(&mut self, ctx: &egui::Context) {
        let Some(shot) = &mut self.screenshot else { return };
        if !shot.requested {
            if shot.delay > 0 {
                shot.delay -= 1;
                ctx.request_repaint();
                return;
            }
            let ready = match shot.after_passes {
                Some(n) => {
                    self.panes.iter().all(|p| p.state.passes() >= n || p.state.finished || p.state.failed.is_some())
                }
                None => true,
            };
            if ready {
                shot.requested = true;
                let (path, crop, result, repaint) = (shot.path.clone(), shot.crop, shot.result.clone(), ctx.clone());
                let pixels_per_point = ctx.pixels_per_point();
                ctx.request_screenshot(move |image| {
                    let outcome = save_screenshot(&image, crop, pixels_per_point, &path);
                    if let Ok(mut slot) = result.lock() {
                        *slot = Some(outcome);
                    }
                    repaint.request_repaint();
                });
            }
            ctx.request_repaint();
            return;
        }
        let outcome = shot.result.lock().ok().and_then(|mut slot| slot.take());
        if let Some(outcome) = outcome {
            let (quit, path) = (shot.quit_after, shot.path.clone());
            self.screenshot = None;
            match outcome {
                Ok(()) => self.status = format!("Saved {}", path.display()),
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
        } else {
            ctx.request_repaint();
        }
    }

    pub fn persisted(&self) -> Persisted {
        Persisted {
            panes: self.panes.iter().map(|p| p.settings.clone()).collect(),
            exposures: self.panes.iter().map(|p| p.exposure).collect(),
            show_plots: self.show_plots,
            recent: self.recent.clone(),
        }
    }
}

/// Per-pane render settings; returns whether the pane must restart.
fn pane_settings_ui(ui: &mut egui::Ui, pane: &mut Pane) -> bool {
    let before = pane.settings.clone();
    let s = &mut pane.settings;
    // The engine's limits, narrowed where a pane cannot use more
    let range = |limit: limits::Limit<u32>| limit.min..=limit.max;
    let mut spp = s.samples_per_pixel.unwrap_or(0);
    ui.add(egui::DragValue::new(&mut spp).range(0..=limits::SAMPLES_PER_PIXEL.max).prefix("spp target (0: none) "));
    s.samples_per_pixel = (spp > 0).then_some(spp);
    let mut budget = s.time_limit.unwrap_or(0.0);
    ui.add(
        egui::DragValue::new(&mut budget)
            .range(0.0..=limits::SECONDS.max)
            .speed(0.5)
            .prefix("time budget s (0: none) "),
    );
    s.time_limit = (budget > 0.0).then_some(budget);
    ui.add(egui::DragValue::new(&mut s.max_depth).range(range(limits::MAX_DEPTH)).prefix("max depth "));
    ui.add(egui::DragValue::new(&mut s.width).range(16..=4096).prefix("width "));
    ui.add(egui::DragValue::new(&mut s.height).range(16..=4096).prefix("height "));
    match &mut s.method {
        Method::Whitted | Method::Path => {}
        Method::Photon(p) => {
            ui.separator();
            let photons = range(limits::PHOTONS);
            let global = egui::DragValue::new(&mut p.global_photons).range(photons.clone()).speed(1000);
            ui.add(global.prefix("global photons "));
            ui.add(egui::DragValue::new(&mut p.caustic_photons).range(photons).speed(1000).prefix("caustic photons "));
            ui.add(egui::DragValue::new(&mut p.k_nearest).range(8..=1000).prefix("k nearest "));
            let radius = egui::DragValue::new(&mut p.max_radius).range(0.0..=1e6).speed(0.001);
            ui.add(radius.prefix("max radius (0: auto) "));
            ui.checkbox(&mut p.final_gather, "final gather");
            ui.add(egui::DragValue::new(&mut p.final_gather_rays).range(1..=1024).prefix("gather rays "));
        }
        Method::Sppm(p) => {
            ui.separator();
            let photons = egui::DragValue::new(&mut p.photons_per_pass).range(range(limits::SPPM_PHOTONS)).speed(1000);
            ui.add(photons.prefix("photons per pass "));
            let radius = egui::DragValue::new(&mut p.initial_radius).range(0.0..=1e6).speed(0.001);
            ui.add(radius.prefix("initial radius (0: auto) "));
            ui.add(egui::Slider::new(&mut p.alpha, 0.05..=1.0).text("α"));
        }
    }
    ui.separator();
    if ui.add(egui::Slider::new(&mut pane.exposure, -8.0..=8.0).text("exposure (stops)")).changed() {
        pane.refresh_texture();
    }
    pane.settings != before
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
        if self.autosave_offer.is_some() {
            return;
        }
        if !self.is_dirty() {
            storage.set_string(AUTOSAVE_KEY, String::new());
            return;
        }
        match to_ron(&self.scene) {
            Ok(text) => storage.set_string(AUTOSAVE_KEY, text),
            Err(e) => self.error = Some(format!("could not autosave the scene: {e}")),
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        // The window is gone: the terminal is the one place left to say it
        if let Err(e) = self.save_state() {
            eprintln!("error: {e}");
        }
    }
}
