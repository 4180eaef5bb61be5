//! The headless side of the binary: `render` (and, as they land, `photons`,
//! `reference`, `bench`). Errors become `anyhow` here, at the edge.

pub mod bench;
pub mod photons;
pub mod reference;
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
    /// Trace a scene's photon maps once and save them for `render --photon-map`.
    Photons(photons::PhotonsArgs),
    /// Render converged path-traced references (EXR, with metadata beside them).
    Reference(reference::ReferenceArgs),
    /// Speed against error: every algorithm for the same time budget, against references.
    Bench(bench::BenchArgs),
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
    #[command(flatten)]
    pub photon: PhotonFlags,
}

/// Photon mapping's knobs; defaults as in `PhotonSettings`.
#[derive(Debug, Args, Clone)]
pub struct PhotonFlags {
    /// Photons emitted for the global map.
    #[arg(long)]
    pub global_photons: Option<u32>,
    /// Photons emitted toward specular objects for the caustic map.
    #[arg(long)]
    pub caustic_photons: Option<u32>,
    /// Photons gathered per estimate (at least 8).
    #[arg(long = "k")]
    pub k_nearest: Option<u32>,
    /// Largest gather radius (scene units; 0 = from the scene's size).
    #[arg(long)]
    pub max_radius: Option<f32>,
    /// Estimate indirect light by a final gather instead of reading the global map directly.
    #[arg(long)]
    pub final_gather: bool,
    /// Rays per final gather.
    #[arg(long)]
    pub gather_rays: Option<u32>,
    /// SPPM: photons per pass.
    #[arg(long)]
    pub sppm_photons: Option<u32>,
    /// SPPM: initial gather radius (0 = from the scene's size).
    #[arg(long)]
    pub sppm_radius: Option<f32>,
    /// SPPM: radius reduction α in (0, 1].
    #[arg(long)]
    pub sppm_alpha: Option<f32>,
}

impl PhotonFlags {
    pub fn apply(&self, settings: &mut crate::render::PhotonSettings) -> anyhow::Result<()> {
        let p = settings;
        if let Some(v) = self.global_photons {
            p.global_photons = v;
        }
        if let Some(v) = self.caustic_photons {
            p.caustic_photons = v;
        }
        if let Some(v) = self.k_nearest {
            p.k_nearest = v.max(8);
        }
        if let Some(v) = self.max_radius {
            anyhow::ensure!(v >= 0.0 && v.is_finite(), "--max-radius must be a finite number ≥ 0");
            p.max_radius = v;
        }
        p.final_gather |= self.final_gather;
        if let Some(v) = self.gather_rays {
            p.final_gather_rays = v.max(1);
        }
        if let Some(v) = self.sppm_photons {
            p.sppm_photons_per_pass = v;
        }
        if let Some(v) = self.sppm_radius {
            anyhow::ensure!(v >= 0.0 && v.is_finite(), "--sppm-radius must be a finite number ≥ 0");
            p.sppm_initial_radius = v;
        }
        if let Some(v) = self.sppm_alpha {
            anyhow::ensure!(v > 0.0 && v <= 1.0, "--sppm-alpha must be in (0, 1]");
            p.sppm_alpha = v;
        }
        Ok(())
    }
}
