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
    if let Some(path) = dropped.into_iter().find(|p| p.extension().is_some_and(|e| e == "ron")) {
        commands.push(Command::Request(Action::Open(path)));
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
