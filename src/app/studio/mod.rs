//! The studio's root: the document, the panes, the dialogs, the capture and
//! the difference view, each its own room. Every frame: take the engine's
//! events, draw (the rooms return commands), apply the commands, and if the
//! scene has a new valid revision, restart every pane with its snapshot.
//! The UI thread never waits on the engine.

use std::path::{Path, PathBuf};

use eframe::egui;

mod drive;

use super::capture::Capture;
use super::commands::{Action, Command, Shown};
use super::dialogs::Dialogs;
use super::difference::Difference;
use super::document::Document;
use super::export::export_image;
use super::files::DialogPurpose;
use super::imports::Imports;
use super::inspector::{inspector_ui, Selection};
use super::keys::{input_commands, Gesture, WindowState};
use super::menu::{menu_bar_ui, MenuView};
use super::pane::Pane;
use super::panes::{pane_count, Panes};
use super::plots::plots_ui;
use super::references::References;
use super::status::{FrameClock, Messages};
use super::storage::{autosave_offer, read_state, remember, write_state, Autosave, Persisted, StateKeeper};
use super::StudioArgs;
use crate::analysis::reference::ReferenceCache;
use crate::render::Workers;
use crate::scene::{presets, Scene};

pub struct StudioApp {
    document: Document,
    panes: Panes,
    references: References,
    selection: Selection,
    dialogs: Dialogs,
    capture: Capture,
    difference: Difference,
    /// Meshes being read for File ▸ Import mesh and dropped files.
    imports: Imports,
    shown: Shown,
    recent: Vec<PathBuf>,
    messages: Messages,
    quit_confirmed: bool,
    state: StateKeeper,
    clock: FrameClock,
    gesture: Gesture,
    /// Where a `--screenshot` run also saves each pane's image.
    save_panes: Option<PathBuf>,
    /// The revision the reference follows.
    referenced_revision: u64,
    paused: bool,
    ctx: egui::Context,
}

impl StudioApp {
    /// Build the studio; `storage` restores layout, settings and recent
    /// files (checked: a bad saved value falls back with a notice).
    pub fn new(ctx: &egui::Context, storage: Option<&dyn eframe::Storage>, args: &StudioArgs) -> Self {
        let (restored, autosaved) = read_state(storage);
        let (document, error) = Document::starting(args.scene.as_deref());
        let capture_only = args.screenshot.is_some();
        // A `--screenshot` run shows the offer as a start would, and leaves
        // it unanswered: it writes nothing
        let autosave_offer = autosave_offer(autosaved, document.scene());
        let count = pane_count(args.panes.unwrap_or(restored.panes.len().max(1)));
        // One pool of every core for all the panes, below the UI's priority
        let (workers, workers_error) = match Workers::new(0) {
            Ok(workers) => (Some(workers), None),
            Err(e) => (None, Some(format!("could not start the render threads: {e}"))),
        };
        let reference_cache = match &args.reference_cache {
            Some(dir) => Some(ReferenceCache::new(dir.clone(), crate::limits::REFERENCE_CACHE_BYTES)),
            None => ReferenceCache::open_default(),
        };
        let mut app = Self {
            references: References::new(ctx, workers.as_ref(), reference_cache),
            panes: Panes::new(ctx, workers),
            document,
            selection: Selection::Camera,
            dialogs: Dialogs::new(autosave_offer, start_folder(&restored.recent)),
            capture: args.screenshot.clone().map_or_else(Capture::default, |path| {
                Capture::headless(path, args.quit_after_passes, args.quit_after_seconds)
            }),
            difference: Difference::default(),
            imports: Imports::default(),
            shown: Shown { plots: restored.show_plots, ..Shown::default() },
            recent: restored.recent,
            messages: Messages { error: error.or(workers_error), status: restored.notices.join("; ") },
            quit_confirmed: false,
            state: StateKeeper::new(capture_only),
            clock: FrameClock::default(),
            gesture: Gesture::default(),
            save_panes: args.save_panes.clone(),
            referenced_revision: 0,
            paused: false,
            ctx: ctx.clone(),
        };
        let saved_panes = if args.panes.is_none() { restored.panes } else { Vec::new() };
        app.panes.build(count, &saved_panes, &restored.exposures, &app.document.scene().settings);
        app.restart_all();
        app
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
            Command::ImportMesh(path) => self.imports.start(path, &self.ctx),
            Command::Undo => self.document.undo(),
            Command::Redo => self.document.redo(),
            Command::SetPanes(count) if count != self.panes.count() => {
                self.panes.set_count(pane_count(count), &self.document.scene().settings);
                self.restart_all();
            }
            Command::SetPanes(_) => {}
            Command::Show(panel, on) => self.shown.set(panel, on),
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
                    self.messages.say(format!("New scene from the {name} preset"));
                }
                Some(Err(e)) => self.messages.fail(e),
                None => self.messages.fail(format!("no preset called {name}")),
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

    fn save_or_ask(&mut self) {
        match self.document.path().map(Path::to_owned) {
            Some(path) => self.save_to(&path),
            None => self.open_dialog(DialogPurpose::SaveScene),
        }
    }

    fn save_to(&mut self, path: &Path) {
        let saved = self.document.save_to(path);
        if saved.is_ok() {
            remember(&mut self.recent, path);
        }
        self.messages.report(saved, || format!("Saved {}", path.display()));
    }

    fn open_dialog(&mut self, purpose: DialogPurpose) {
        self.dialogs.open_file(purpose, self.document.path());
    }

    /// Act on a path the file dialog chose.
    fn write_chosen(&mut self, purpose: DialogPurpose, path: PathBuf) {
        match purpose {
            DialogPurpose::OpenScene => self.apply(Command::Request(Action::Open(path))),
            DialogPurpose::SaveScene => self.save_to(&path),
            DialogPurpose::ImportMesh => self.apply(Command::ImportMesh(path)),
            DialogPurpose::ExportImage { pane, .. } => self.export_pane(pane, &path),
            DialogPurpose::Screenshot => self.take_screenshot(path, None),
            DialogPurpose::ComparisonSheet => self.take_screenshot(path, Some(self.panes.area())),
        }
    }

    /// Save the window (or, for the comparison sheet, the panes' area with
    /// their labels) as PNG a few frames on.
    fn take_screenshot(&mut self, path: PathBuf, crop: Option<egui::Rect>) {
        if let Err(e) = self.capture.ask(path, crop) {
            self.messages.fail(e);
        }
    }

    // ---- The frame -----------------------------------------------------------

    /// A close asked for with unsaved edits waits for the user's answer;
    /// rendering pauses while the window is minimised.
    fn window_events(&mut self, ctx: &egui::Context, window: WindowState) {
        if window.close_requested && self.document.is_dirty() && !self.quit_confirmed {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.dialogs.ask_unsaved(Action::Quit);
        }
        if window.minimised && !self.paused {
            self.panes.pause_all();
            self.paused = true;
        } else if !window.minimised && self.paused {
            self.paused = false;
            self.restart_all();
        }
    }

    /// One frame of the whole studio.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        self.show_timed(ui, None);
    }

    /// `show`, told what the previous frame cost (by eframe).
    fn show_timed(&mut self, ui: &mut egui::Ui, previous_frame_cost: Option<f32>) {
        let ctx = ui.ctx().clone();
        self.clock.tick(previous_frame_cost);
        if let Some(message) = self.references.poll() {
            self.messages.fail(message);
        }
        self.panes.poll(self.references.reference());
        let mut commands = Vec::new();
        let window = input_commands(&ctx, &mut commands);
        self.window_events(&ctx, window);

        egui::Panel::top("menu").show(ui, |ui| {
            let view = MenuView {
                can_undo: self.document.can_undo(),
                can_redo: self.document.can_redo(),
                recent: &self.recent,
                panes: self.panes.list().iter().map(Pane::algorithm).collect(),
                shown: self.shown,
                file: self.document.path().map(|p| (p, self.document.is_dirty())),
            };
            menu_bar_ui(ui, &view, &mut commands);
        });
        self.messages.status_ui(ui);
        if self.imports.is_reading() {
            egui::Panel::bottom("imports").show(ui, |ui| ui.horizontal(|ui| self.imports.reading_ui(ui)));
        }
        egui::Panel::bottom("reference").show(ui, |ui| self.references.reference_ui(ui));
        egui::Panel::left("inspector").resizable(true).default_size(330.0).show(ui, |ui| {
            let problems = self.document.problems().to_vec();
            let spot = self.document.spot_in_view();
            if inspector_ui(ui, self.document.scene_mut(), &mut self.selection, &problems, spot) {
                self.document.changed();
            }
        });
        if self.shown.plots {
            egui::Panel::bottom("plots").resizable(true).default_size(200.0).show(ui, |ui| {
                // Its size is the user's: content that grows scrolls
                // instead of pushing the panes up as passes come in
                let height = ui.available_height();
                egui::ScrollArea::vertical()
                    .auto_shrink([false, false])
                    .show(ui, |ui| plots_ui(ui, self.panes.list(), height));
            });
        }
        let promoted = egui::CentralPanel::default()
            .show(ui, |ui| {
                self.panes.panes_ui(ui, &mut self.document, &mut self.selection, self.references.reference())
            })
            .inner;
        self.dialogs.dialogs_ui(&ctx, self.document.path(), &mut commands);
        if self.shown.difference {
            self.difference.difference_ui(&ctx, &self.panes, self.references.reference());
        }
        for command in commands {
            self.apply(command);
        }
        self.add_imported();
        if let Some(index) = promoted {
            self.promote_pane(index);
        }

        // A drag, or wheel notches in a row, is one edit: one undo step and
        // one reference, while the panes follow every frame of it
        let interacting = self.gesture.interacting(&ctx);
        self.document.commit(interacting);
        if let Some(scene) = self.document.check() {
            if !self.paused {
                self.panes.restart_all(&scene);
            }
        }
        if !interacting && !self.paused {
            self.follow_with_reference();
        }
        self.capture_step(&ctx);
        if let Err(e) = self.save_state(false) {
            self.messages.fail(e);
        }
        // An edit made just before the studio went idle is still written
        if let Some(wait) = self.state.due_in() {
            ctx.request_repaint_after(wait);
        }
        if self.shown.debug {
            self.clock.debug_ui(&ctx);
        }
    }

    fn capture_step(&mut self, ctx: &egui::Context) {
        let panes = &self.panes;
        let Some(done) = self.capture.step(ctx, |passes| panes.all_have(passes)) else { return };
        match done.result {
            Ok(path) => self.messages.say(format!("Saved {}", path.display())),
            Err(e) => self.messages.fail(e),
        }
        if done.quit {
            // What a headless run measured, for the README's figures and CI
            if let Some(frames) = self.clock.summary() {
                println!("{frames}");
            }
            for (i, pane) in self.panes.list().iter().enumerate() {
                println!("pane {}: {}", i + 1, pane.label());
            }
            if let Some(folder) = &self.save_panes {
                for (i, pane) in self.panes.list().iter().enumerate() {
                    let path = folder.join(format!("pane-{}.exr", i + 1));
                    match export_image(&pane.state().image, pane.exposure(), &path) {
                        Ok(()) => println!("saved {}", path.display()),
                        Err(e) => eprintln!("error: {e}"),
                    }
                }
            }
            println!("{}", self.references.describe());
            if let Some(edits) = self.dialogs.offered_edits() {
                println!("offered back: the last session's unsaved scene ({})", edits.join(", "));
            }
            if let Some(after) = self.references.first_estimate_after() {
                println!("reference: first own estimate {:.2} s after the scene was loaded", after.as_secs_f64());
            }
            self.quit_confirmed = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    /// The meshes read since the last frame join the scene, each selected.
    fn add_imported(&mut self) {
        for (path, read) in self.imports.finished() {
            match read {
                Ok(mesh) => {
                    self.selection = Selection::Object(self.document.add_mesh(&path, mesh));
                    self.messages.say(format!("Imported {}", path.display()));
                }
                Err(e) => self.messages.fail(e),
            }
        }
    }

    // ---- What survives a restart ---------------------------------------------

    /// Write the state file (layout and autosave), if there is one and a
    /// write is due (or `now`).
    fn save_state(&mut self, now: bool) -> Result<(), String> {
        let Some(mut file) = self.state.take(now) else { return Ok(()) };
        eframe::App::save(self, &mut file);
        self.state.put_back(file)
    }
}

/// Where the file dialogs start: the folder of the file used last, else
/// the folder the studio was started from.
fn start_folder(recent: &[PathBuf]) -> PathBuf {
    let last = recent.first().and_then(|p| p.parent()).filter(|f| !f.as_os_str().is_empty());
    last.map(Path::to_owned).or_else(|| std::env::current_dir().ok()).unwrap_or_default()
}

impl eframe::App for StudioApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.show_timed(ui, frame.info().cpu_usage);
    }

    /// The layout and the autosave. A `--screenshot` run writes neither; while
    /// the last session's scene is offered back, its autosave stays as it is
    /// (a second crash must not lose it).
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.state.read_only() {
            return;
        }
        let autosave = match self.document.autosave_text() {
            _ if self.dialogs.offers_autosave() => Autosave::Keep,
            None => Autosave::Clear,
            Some(Ok(text)) => Autosave::Scene(text),
            Some(Err(e)) => {
                self.messages.fail(format!("could not autosave the scene: {e}"));
                Autosave::Keep
            }
        };
        let persisted = Persisted::of(&self.panes, self.shown.plots, &self.recent);
        if let Err(e) = write_state(storage, &persisted, autosave) {
            self.messages.fail(e);
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.save_state_at_exit();
    }
}

impl StudioApp {
    fn save_state_at_exit(&mut self) {
        // The window is gone: the terminal is the one place left to say it
        if let Err(e) = self.save_state(true) {
            eprintln!("error: {e}");
        }
    }
}

/// A studio dropped without `on_exit` (a panic unwinding through the window
/// system's loop: winit's X11 code panics when the X server destroys the
/// window under it) still writes what it keeps; after `on_exit` nothing has
/// changed and nothing is written.
impl Drop for StudioApp {
    fn drop(&mut self) {
        self.save_state_at_exit();
    }
}
