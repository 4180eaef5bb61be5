//! The status bar (the last error, or news) and the debug overlay's frame
//! time.

use std::time::Instant;

use eframe::egui;

/// How soon a pass's progress from the engine is drawn: often enough to
/// look live, seldom enough that drawing leaves the cores to the renders.
/// Under software GL a frame of four panes costs most of a core to
/// present, which a faster rate takes from the renders.
pub const RENDER_REPAINT: std::time::Duration = std::time::Duration::from_millis(200);

/// Ask for a frame for the engine's news (at once) or progress (soon).
pub fn repaint(ctx: &egui::Context, news: bool) {
    if news {
        ctx.request_repaint();
    } else {
        ctx.request_repaint_after(RENDER_REPAINT);
    }
}

/// Frames a clock remembers for its summary.
const KEPT_FRAMES: usize = 4096;

/// What UI frames cost: the CPU time of each (building the UI and painting
/// it, not waiting for the display; eframe measures it), smoothed for the
/// overlay and kept for the last few thousand frames, and the time between
/// frames.
#[derive(Default)]
pub struct FrameClock {
    last: Option<Instant>,
    interval_ms: f32,
    cost_ms: f32,
    costs_ms: std::collections::VecDeque<f32>,
}

impl FrameClock {
    /// A new frame, which says what the previous one cost (None: unknown,
    /// as in tests without a window).
    pub fn tick(&mut self, previous_cost: Option<f32>) {
        let now = Instant::now();
        if let Some(last) = self.last {
            self.interval_ms = 0.9 * self.interval_ms + 0.1 * (now - last).as_secs_f32() * 1e3;
        }
        self.last = Some(now);
        if let Some(ms) = previous_cost.map(|seconds| seconds * 1e3).filter(|ms| ms.is_finite()) {
            self.cost_ms = 0.9 * self.cost_ms + 0.1 * ms;
            if self.costs_ms.len() == KEPT_FRAMES {
                self.costs_ms.pop_front();
            }
            self.costs_ms.push_back(ms);
        }
    }

    /// "N UI frames: median M ms, 95th percentile P ms" (None before any).
    pub fn summary(&self) -> Option<String> {
        let mut sorted: Vec<f32> = self.costs_ms.iter().copied().collect();
        if sorted.is_empty() {
            return None;
        }
        sorted.sort_by(f32::total_cmp);
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        Some(format!("{} UI frames: median {:.1} ms, 95th percentile {:.1} ms", sorted.len(), at(0.5), at(0.95)))
    }

    pub fn debug_ui(&self, ctx: &egui::Context) {
        let area = egui::Area::new(egui::Id::unique("debug")).anchor(egui::Align2::RIGHT_TOP, egui::vec2(-8.0, 28.0));
        area.show(ctx, |ui| {
            let text =
                egui::RichText::new(format!("UI frame {:.1} ms, every {:.0} ms", self.cost_ms, self.interval_ms))
                    .monospace();
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

    /// Say `done` if `result` went well (an error from an earlier try
    /// is over), its error otherwise.
    pub fn report<E: ToString>(&mut self, result: Result<(), E>, done: impl FnOnce() -> String) {
        match result {
            Ok(()) => {
                self.error = None;
                self.say(done());
            }
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
