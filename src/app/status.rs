//! The status bar (the last error, or news) and the debug overlay's frame
//! time.

use std::time::Instant;

use eframe::egui;

/// A smoothed time per UI frame.
#[derive(Default)]
pub struct FrameClock {
    last: Option<Instant>,
    ms: f32,
}

impl FrameClock {
    pub fn tick(&mut self) {
        let now = Instant::now();
        if let Some(last) = self.last {
            self.ms = 0.9 * self.ms + 0.1 * (now - last).as_secs_f32() * 1e3;
        }
        self.last = Some(now);
    }

    pub fn debug_ui(&self, ctx: &egui::Context) {
        let area = egui::Area::new(egui::Id::unique("debug")).anchor(egui::Align2::RIGHT_TOP, egui::vec2(-8.0, 28.0));
        area.show(ctx, |ui| {
            let text = egui::RichText::new(format!("UI frame {:.1} ms", self.ms)).monospace();
            ui.label(text.background_color(egui::Color32::from_black_alpha(180)));
        });
        ctx.request_repaint();
    }
}

/// What the status bar says: the last error, until dismissed, else news.
#[derive(Default)]
pub struct Messages {
    pub error: Option<String>,
    pub status: String,
}

impl Messages {
    pub fn fail(&mut self, message: impl ToString) {
        self.error = Some(message.to_string());
    }

    pub fn say(&mut self, message: impl ToString) {
        self.status = message.to_string();
    }

    /// Add a line to what the status bar says.
    pub fn notice(&mut self, message: &str) {
        if message.is_empty() {
            return;
        }
        if !self.status.is_empty() {
            self.status += "; ";
        }
        self.status += message;
    }

    /// Say `done` if `result` went well, its error otherwise.
    pub fn report<E: ToString>(&mut self, result: Result<(), E>, done: impl FnOnce() -> String) {
        match result {
            Ok(()) => self.say(done()),
            Err(e) => self.fail(e),
        }
    }

    /// The bottom line: the error in red with a way to dismiss it, else the news.
    pub fn status_ui(&mut self, ui: &mut egui::Ui) {
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| match &self.error {
                Some(message) => {
                    ui.colored_label(ui.visuals().error_fg_color, message.as_str());
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
}
