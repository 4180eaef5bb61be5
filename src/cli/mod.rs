//! The headless side of the binary: `render` (and, as they land, `photons`,
//! `reference`, `bench`). Errors become `anyhow` here, at the edge.

pub mod render;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::render::Algorithm;

#[derive(Debug, Parser)]
#[command(
    name = "gi-studio",
    version,
    about = "A studio for global illumination: Whitted ray tracing, path tracing, photon mapping and progressive photon mapping side by side."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub studio: StudioArgs,
}

/// Options of the studio window (no subcommand).
#[derive(Debug, Args, Default, Clone)]
pub struct StudioArgs {
    /// Open this scene file instead of the built-in Cornell box.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Number of viewport panes (1, 2 or 4).
    #[arg(long)]
    pub panes: Option<usize>,
    /// Save a screenshot of the window here once the panes have rendered
    /// `--quit-after-passes` passes, then exit (for CI and the README).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    #[arg(long, default_value_t = 2)]
    pub quit_after_passes: u32,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene file to PNG (tone-mapped) or EXR (linear).
    Render(render::RenderArgs),
}

/// Flags shared by every command that renders.
#[derive(Debug, Args, Clone)]
pub struct RenderFlags {
    /// whitted, path, photon or sppm.
    #[arg(long = "algo", default_value = "path")]
    pub algorithm: Algorithm,
    /// Samples per pixel (passes); the default is 64 unless --time is given.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Render for this many seconds of wall-clock time instead.
    #[arg(long)]
    pub time: Option<f64>,
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0: every core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Longest path (the algorithm's default if not given).
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// Exposure in stops for PNG output (the scene's if not given).
    #[arg(long)]
    pub exposure: Option<f32>,
    /// Limit every sample's channels to this value (off by default: it biases).
    #[arg(long, default_value_t = 0.0)]
    pub clamp: f32,
}
