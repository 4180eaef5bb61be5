//! What the keyboard, dropped files and the window ask for, as commands.

use std::path::PathBuf;

use eframe::egui;

use super::commands::{Action, Command};
use super::files::DialogPurpose;

/// This frame's shortcuts and drops, and whether the window asks to close
/// and is minimised.
pub fn input_commands(ctx: &egui::Context, commands: &mut Vec<Command>) -> WindowState {
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
    let extension = |p: &PathBuf| p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    for path in dropped {
        match extension(&path).as_deref() {
            Some("obj" | "ply") => commands.push(Command::ImportMesh(path)),
            Some("ron") => commands.push(Command::Request(Action::Open(path))),
            _ => {}
        }
    }
    WindowState {
        close_requested: ctx.input(|i| i.viewport().close_requested()),
        minimised: ctx.input(|i| i.viewport().minimized).unwrap_or(false),
    }
}

pub struct WindowState {
    pub close_requested: bool,
    pub minimised: bool,
}

/// Seconds between wheel notches that still belong to one gesture.
const WHEEL_GESTURE_GAP: f64 = 0.5;

/// Whether the user is in the middle of a gesture: a button held (a drag),
/// or the wheel turned within the last half second (a dolly of several
/// notches, which egui spreads over many frames).
#[derive(Default)]
pub struct Gesture {
    last_wheel: Option<f64>,
}

impl Gesture {
    pub fn interacting(&mut self, ctx: &egui::Context) -> bool {
        let (now, wheel, held) = ctx.input(|i| {
            let wheel = i.is_scrolling() || i.smooth_scroll_delta != egui::Vec2::ZERO;
            (i.time, wheel, i.pointer.any_down())
        });
        if wheel {
            self.last_wheel = Some(now);
        }
        let turning = self.last_wheel.is_some_and(|at| now - at < WHEEL_GESTURE_GAP);
        if turning {
            // The gesture ends with no input to say so: a frame when it has
            ctx.request_repaint_after(std::time::Duration::from_secs_f64(WHEEL_GESTURE_GAP));
        }
        held || turning
    }
}
