//! The studio window (eframe/egui). It depends on every layer below; none
//! depends on it. It reaches the engine only through `RenderSession`s. The
//! rooms: the document (scene, file, history), the panes, the dialogs, the
//! capture of screenshots, the difference view, the plots; the menus and
//! dialogs return commands that `studio` applies once per frame.

mod capture;
mod commands;
mod dialogs;
mod difference;
mod document;
mod export;
mod files;
mod handles;
mod history;
mod image_view;
mod imports;
mod inspector;
mod keys;
mod menu;
mod outline;
mod pane;
mod panes;
mod plots;
mod readout;
mod references;
mod status;
mod storage;
mod strategies;
mod studio;
mod viewport;
mod widgets;
mod window_lost;
mod wipe;
pub use wipe::Against;

pub use commands::Action;
pub use inspector::Selection;
pub use pane::{Pane, PaneError, PaneState, PassRecord};
pub use panes::{Panes, FOUR as FOUR_PANES};
pub use references::{Progress, References, Source};
pub use status::Messages;
pub use storage::{Persisted, StateFile, SAVE_INTERVAL};
pub use studio::StudioApp;

use std::path::PathBuf;

use clap::Args;

/// Options of the studio window (the binary without a subcommand).
#[derive(Debug, Args, Default, Clone)]
pub struct StudioArgs {
    /// Open this scene file instead of the built-in Cornell box.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Number of viewport panes (1, 2 or 4).
    #[arg(long, value_parser = parse_panes)]
    pub panes: Option<usize>,
    /// Save a PNG screenshot of the window here once the panes have
    /// rendered `--quit-after-passes` passes, then exit (for CI and the
    /// README). Such a run saves no settings and touches no autosave.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    #[arg(long, default_value_t = 2, value_parser = |s: &str| crate::limits::SAMPLES_PER_PIXEL.parse(s))]
    pub quit_after_passes: u32,
    /// With --screenshot: take it this many seconds after the start, however
    /// many passes the panes have (instead of --quit-after-passes).
    #[arg(long, value_parser = |s: &str| crate::limits::SECONDS.parse(s))]
    pub quit_after_seconds: Option<f64>,
    /// With --screenshot: also save each pane's linear image there, as
    /// pane-1.exr, pane-2.exr… (for measuring what the panes showed).
    #[arg(long, value_name = "DIR")]
    pub save_panes: Option<PathBuf>,
    /// Replace a screenshot file that GI Studio did not write.
    #[arg(long)]
    pub force: bool,
    /// Keep references rendered for edited scenes in DIR (default:
    /// $XDG_CACHE_HOME/gistudio/references, or ~/.cache/gistudio/references).
    #[arg(long, value_name = "DIR")]
    pub reference_cache: Option<PathBuf>,
}

fn parse_panes(text: &str) -> Result<usize, String> {
    match text.trim() {
        "1" => Ok(1),
        "2" => Ok(2),
        "4" => Ok(4),
        other => Err(format!("must be 1, 2 or 4, found {other}")),
    }
}

/// Open the studio and run until the window closes.
pub fn run(args: StudioArgs) -> anyhow::Result<()> {
    if let Some(path) = &args.screenshot {
        capture::check_screenshot_path(path, args.force)?;
    }
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_inner_size([1480.0, 920.0])
            .with_title("GI Studio")
            .with_drag_and_drop(true),
        ..Default::default()
    };
    let (state, notice) = match storage::state_folder() {
        Some(folder) => {
            let (file, notice) = storage::StateFile::open(folder.join("app.ron"));
            (Some(file), notice)
        }
        None => (None, None),
    };
    let mut exit_error = None;
    let window = window_lost::catching_window_loss(|| {
        eframe::run_native(
            "GI Studio",
            options,
            Box::new(|cc| {
                let mut app = StudioApp::new(&cc.egui_ctx, state.as_ref().map(|s| s as &dyn eframe::Storage), &args);
                app.notice(&notice.unwrap_or_default());
                // A scene that would not open (`--scene`) is said where the
                // command was typed too, not only in the status bar
                if let Some(error) = &app.messages().error {
                    eprintln!("error: {error}");
                }
                if let Some(file) = state {
                    app.keep_state_in(file, storage::SAVE_INTERVAL);
                }
                exit_error = Some(app.exit_error());
                Ok(Box::new(app))
            }),
        )
    });
    match window {
        Ok(opened) => opened.map_err(|e| anyhow::anyhow!("could not open the studio window: {e}"))?,
        // A window taken away is closed: the studio wrote its state as it went
        Err(lost) => eprintln!("The window system destroyed the window ({}); the studio closed.", lost.0),
    }
    if let Some(message) = exit_error.and_then(|slot| slot.lock().ok().and_then(|mut m| m.take())) {
        anyhow::bail!(message);
    }
    Ok(())
}
