//! The studio window (eframe/egui). It depends on every layer below; none
//! depends on it. It reaches the engine only through `RenderSession`s.

mod export;
mod files;
mod history;
mod inspector;
mod menu;
mod pane;
mod plots;
mod studio;
mod viewport;

pub use inspector::Selection;
pub use pane::{Pane, PaneState, PassRecord};
pub use studio::{Action, Persisted, StudioApp};
pub use viewport::pick;

use crate::cli::StudioArgs;

/// Open the studio and run until the window closes.
pub fn run(args: StudioArgs) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_inner_size([1480.0, 920.0])
            .with_title("GI Studio")
            .with_drag_and_drop(true),
        ..Default::default()
    };
    let mut exit_error = None;
    eframe::run_native(
        "GI Studio",
        options,
        Box::new(|cc| {
            let app = StudioApp::new(&cc.egui_ctx, cc.storage, &args);
            exit_error = Some(app.exit_error.clone());
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow::anyhow!("could not open the studio window: {e}"))?;
    if let Some(message) = exit_error.and_then(|slot| slot.lock().ok().and_then(|mut m| m.take())) {
        anyhow::bail!(message);
    }
    Ok(())
}
