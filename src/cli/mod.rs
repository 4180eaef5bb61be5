//! The headless side of the binary: `render`, `photons`, `reference` and
//! `bench`. Errors become `anyhow` here, at the edge. Every flag is checked
//! against `crate::limits` as it is parsed.

pub mod bench;
pub mod farm;
pub mod merge;
pub mod merges;
pub mod outputs;
pub mod photons;
pub mod reference;
pub mod render;
pub mod shard;

use clap::{Args, Parser, Subcommand};

use crate::limits;
use crate::render::{Algorithm, MergeSettings, Method, MisHeuristic, PhotonSettings, SppmSettings, DEPTH_MEANING};
use merges::Merges;

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
    /// Render converged references (EXR with each pixel's variance, metadata beside it) by the method each scene needs.
    Reference(reference::ReferenceArgs),
    /// Speed against error: every algorithm for the same time budget, against references.
    Bench(bench::BenchArgs),
    /// Join the partials of a render split by `render --shard` into one image.
    Merge(merge::MergeArgs),
    /// How far one image is from another (relMSE, RMSE, the largest difference).
    Compare(merge::CompareArgs),
    /// Scripts that render a scene as shards on a SLURM or Kubernetes cluster, then merge them.
    Farm(farm::FarmArgs),
}

/// Flags shared by every command that renders.
#[derive(Debug, Args, Clone)]
pub struct RenderFlags {
    /// whitted, path, photon, sppm, lt, bdpt, bpm or vcm.
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
    #[arg(long, help = DEPTH_MEANING, value_parser = |s: &str| limits::MAX_DEPTH.parse(s))]
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
    #[command(flatten)]
    pub sppm: SppmFlags,
    #[command(flatten)]
    pub bidir: BidirFlags,
}

/// Photon mapping's knobs; defaults as in `PhotonSettings`.
#[derive(Debug, Args, Clone)]
#[command(next_help_heading = "Photon mapping (--algo photon, and the photons command)")]
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
}

impl PhotonFlags {
    /// The first flag given, if any (to refuse it where it does not apply).
    fn given(&self) -> Option<&'static str> {
        [
            (self.global_photons.is_some(), "--global-photons"),
            (self.caustic_photons.is_some(), "--caustic-photons"),
            (self.k_nearest.is_some(), "--k"),
            (self.max_radius.is_some(), "--max-radius"),
            (self.final_gather, "--final-gather"),
            (self.gather_rays.is_some(), "--gather-rays"),
        ]
        .into_iter()
        .find_map(|(given, name)| given.then_some(name))
    }

    /// The flags given, over `p` (each was checked as it was parsed).
    pub fn apply(&self, p: &mut PhotonSettings) {
        p.global_photons = self.global_photons.unwrap_or(p.global_photons);
        p.caustic_photons = self.caustic_photons.unwrap_or(p.caustic_photons);
        p.k_nearest = self.k_nearest.unwrap_or(p.k_nearest);
        p.max_radius = self.max_radius.unwrap_or(p.max_radius);
        p.final_gather |= self.final_gather;
        p.final_gather_rays = self.gather_rays.unwrap_or(p.final_gather_rays);
    }
}

/// Progressive photon mapping's knobs; defaults as in `SppmSettings`.
#[derive(Debug, Args, Clone)]
#[command(next_help_heading = "Progressive photon mapping (--algo sppm)")]
pub struct SppmFlags {
    /// Photons per pass.
    #[arg(long, value_parser = |s: &str| limits::SPPM_PHOTONS.parse(s))]
    pub sppm_photons: Option<u32>,
    /// Initial gather radius (0 = from the scene's size).
    #[arg(long, value_parser = |s: &str| limits::LENGTH.parse(s))]
    pub sppm_radius: Option<f32>,
    /// Radius reduction α in (0, 1].
    #[arg(long, value_parser = |s: &str| limits::SPPM_ALPHA.parse(s))]
    pub sppm_alpha: Option<f32>,
}

impl SppmFlags {
    fn given(&self) -> Option<&'static str> {
        [
            (self.sppm_photons.is_some(), "--sppm-photons"),
            (self.sppm_radius.is_some(), "--sppm-radius"),
            (self.sppm_alpha.is_some(), "--sppm-alpha"),
        ]
        .into_iter()
        .find_map(|(given, name)| given.then_some(name))
    }

    pub fn apply(&self, p: &mut SppmSettings) {
        p.photons_per_pass = self.sppm_photons.unwrap_or(p.photons_per_pass);
        p.initial_radius = self.sppm_radius.unwrap_or(p.initial_radius);
        p.alpha = self.sppm_alpha.unwrap_or(p.alpha);
    }
}

/// The bidirectional methods' knobs; defaults as in `BidirSettings` and
/// `MergeSettings`.
#[derive(Debug, Args, Clone)]
#[command(next_help_heading = "Bidirectional methods (--algo lt, bdpt, bpm, vcm)")]
pub struct BidirFlags {
    /// How strategies are weighed: power or balance (bdpt, bpm, vcm).
    #[arg(long)]
    pub mis: Option<MisHeuristic>,
    /// Merge radius at the first pass (bpm, vcm; 0 = 2% of what the camera sees for bpm, 1% for vcm, 0.5% for vcm merging everywhere).
    #[arg(long, value_parser = |s: &str| limits::LENGTH.parse(s))]
    pub merge_radius: Option<f32>,
    /// Merge radius reduction α in (0, 1] (bpm, vcm).
    #[arg(long, value_parser = |s: &str| limits::SPPM_ALPHA.parse(s))]
    pub merge_alpha: Option<f32>,
    /// Where VCM merges: caustics (only where light came through a mirror or glass; connections make every other path) or everywhere (Georgiev et al. 2012) [default: caustics].
    #[arg(long, value_enum)]
    pub merges: Option<Merges>,
}

impl BidirFlags {
    fn given_mis(&self) -> Option<&'static str> {
        self.mis.is_some().then_some("--mis")
    }

    fn given_merge(&self) -> Option<&'static str> {
        [(self.merge_radius.is_some(), "--merge-radius"), (self.merge_alpha.is_some(), "--merge-alpha")]
            .into_iter()
            .find_map(|(given, name)| given.then_some(name))
    }

    fn given_merge_rule(&self) -> Option<&'static str> {
        self.merges.is_some().then_some("--merges")
    }

    fn given(&self) -> Option<&'static str> {
        self.given_mis().or(self.given_merge()).or(self.given_merge_rule())
    }

    pub fn apply(&self, m: &mut MergeSettings) {
        m.mis = self.mis.unwrap_or(m.mis);
        m.radius = self.merge_radius.unwrap_or(m.radius);
        m.alpha = self.merge_alpha.unwrap_or(m.alpha);
        if let Some(merges) = self.merges {
            merges.apply(m);
        }
    }
}

impl RenderFlags {
    /// `algorithm` with the knobs the flags give it; a knob of another
    /// algorithm is refused, naming both.
    pub fn method(&self, algorithm: Algorithm) -> anyhow::Result<Method> {
        let mut method = Method::of(algorithm);
        let (photon, sppm, bidir) = (&self.photon, &self.sppm, &self.bidir);
        let misplaced = match &mut method {
            Method::Photon(p) => {
                photon.apply(p);
                sppm.given().or(bidir.given())
            }
            Method::Sppm(p) => {
                sppm.apply(p);
                photon.given().or(bidir.given())
            }
            Method::Bdpt(b) => {
                b.mis = bidir.mis.unwrap_or(b.mis);
                photon.given().or(sppm.given()).or(bidir.given_merge()).or(bidir.given_merge_rule())
            }
            Method::Bpm(m) => {
                bidir.apply(m);
                // Merges are its only strategy
                photon.given().or(sppm.given()).or(bidir.given_merge_rule())
            }
            Method::Vcm(m) => {
                bidir.apply(m);
                photon.given().or(sppm.given())
            }
            Method::Whitted | Method::Path | Method::LightTracing => photon.given().or(sppm.given()).or(bidir.given()),
        };
        match misplaced {
            Some(flag) => anyhow::bail!("{flag} does not apply to --algo {algorithm}"),
            None => Ok(method),
        }
    }
}
