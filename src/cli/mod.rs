//! The headless side of the binary: `render`, `photons`, `reference` and
//! `bench`. Errors become `anyhow` here, at the edge. Every flag is checked
//! against `crate::limits` as it is parsed.

pub mod bench;
pub mod outputs;
pub mod photons;
pub mod reference;
pub mod render;

use clap::{Args, Parser, Subcommand};

use crate::limits;
use crate::render::Algorithm;

/// The headless commands alone (the binary adds the studio's flags).
#[derive(Debug, Parser)]
#[command(name = "gi-studio")]
pub struct Headless {
    #[command(subcommand)]
    pub command: Command,
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
    #[arg(long, value_parser = |s: &str| limits::SAMPLES_PER_PIXEL.parse(s))]
    pub spp: Option<u32>,
    /// Render for this many seconds of wall-clock time instead.
    #[arg(long, value_parser = |s: &str| limits::SECONDS.parse(s))]
    pub time: Option<f64>,
    #[arg(long, value_parser = |s: &str| limits::IMAGE_SIDE.parse(s))]
    pub width: Option<u32>,
    #[arg(long, value_parser = |s: &str| limits::IMAGE_SIDE.parse(s))]
    pub height: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0: every core).
    #[arg(long, default_value_t = 0, value_parser = |s: &str| limits::THREADS.parse(s))]
    pub threads: usize,
    /// Longest path (the algorithm's default if not given).
    #[arg(long, value_parser = |s: &str| limits::MAX_DEPTH.parse(s))]
    pub max_depth: Option<u32>,
    /// Exposure in stops for PNG output (the scene's if not given).
    #[arg(long, value_parser = |s: &str| limits::EXPOSURE_STOPS.parse(s))]
    pub exposure: Option<f32>,
    /// Limit every sample's channels to this value (off by default: it biases).
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| limits::LENGTH.parse(s))]
    pub clamp: f32,
    /// Replace output files that GI Studio did not write (never the inputs).
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub photon: PhotonFlags,
}

/// Photon mapping's knobs; defaults as in `PhotonSettings`.
#[derive(Debug, Args, Clone)]
pub struct PhotonFlags {
    /// Photons emitted for the global map.
    #[arg(long, value_parser = |s: &str| limits::PHOTONS.parse(s))]
    pub global_photons: Option<u32>,
    /// Photons emitted toward specular objects for the caustic map.
    #[arg(long, value_parser = |s: &str| limits::PHOTONS.parse(s))]
    pub caustic_photons: Option<u32>,
    /// Photons gathered per estimate.
    #[arg(long = "k", value_parser = |s: &str| limits::K_NEAREST.parse(s))]
    pub k_nearest: Option<u32>,
    /// Largest gather radius (scene units; 0 = from the scene's size).
    #[arg(long, value_parser = |s: &str| limits::LENGTH.parse(s))]
    pub max_radius: Option<f32>,
    /// Estimate indirect light by a final gather instead of reading the global map directly.
    #[arg(long)]
    pub final_gather: bool,
    /// Rays per final gather.
    #[arg(long, value_parser = |s: &str| limits::GATHER_RAYS.parse(s))]
    pub gather_rays: Option<u32>,
    /// SPPM: photons per pass.
    #[arg(long, value_parser = |s: &str| limits::SPPM_PHOTONS.parse(s))]
    pub sppm_photons: Option<u32>,
    /// SPPM: initial gather radius (0 = from the scene's size).
    #[arg(long, value_parser = |s: &str| limits::LENGTH.parse(s))]
    pub sppm_radius: Option<f32>,
    /// SPPM: radius reduction α in (0, 1].
    #[arg(long, value_parser = |s: &str| limits::SPPM_ALPHA.parse(s))]
    pub sppm_alpha: Option<f32>,
}

impl PhotonFlags {
    /// The flags given, over `settings` (each was checked as it was parsed).
    pub fn apply(&self, settings: &mut crate::render::PhotonSettings) {
        let p = settings;
        let set = |target: &mut u32, value: Option<u32>| *target = value.unwrap_or(*target);
        set(&mut p.global_photons, self.global_photons);
        set(&mut p.caustic_photons, self.caustic_photons);
        set(&mut p.k_nearest, self.k_nearest);
        set(&mut p.final_gather_rays, self.gather_rays);
        set(&mut p.sppm_photons_per_pass, self.sppm_photons);
        p.max_radius = self.max_radius.unwrap_or(p.max_radius);
        p.sppm_initial_radius = self.sppm_radius.unwrap_or(p.sppm_initial_radius);
        p.sppm_alpha = self.sppm_alpha.unwrap_or(p.sppm_alpha);
        p.final_gather |= self.final_gather;
    }
}
