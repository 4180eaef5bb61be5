//! What to render and how long: the algorithm and its knobs.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::limits::{self, OutOfRange};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Algorithm {
    Whitted,
    Path,
    Photon,
    Sppm,
}

impl Algorithm {
    pub const ALL: [Algorithm; 4] = [Algorithm::Whitted, Algorithm::Path, Algorithm::Photon, Algorithm::Sppm];

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Whitted => "whitted",
            Algorithm::Path => "path",
            Algorithm::Photon => "photon",
            Algorithm::Sppm => "sppm",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Algorithm::Whitted => "Whitted ray tracing",
            Algorithm::Path => "Path tracing",
            Algorithm::Photon => "Photon mapping",
            Algorithm::Sppm => "Progressive photon mapping",
        }
    }

    /// The thesis' depth 5 for Whitted; the Monte Carlo methods end paths by
    /// Russian roulette well before their cap.
    pub fn default_max_depth(self) -> u32 {
        match self {
            Algorithm::Whitted => 5,
            _ => 32,
        }
    }
}

impl fmt::Display for Algorithm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Algorithm {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Algorithm::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown algorithm \"{s}\" (expected whitted, path, photon or sppm)"))
    }
}

/// Photon mapping's knobs (Jensen's two maps, and SPPM).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PhotonSettings {
    pub global_photons: u32,
    pub caustic_photons: u32,
    /// Photons gathered per radiance estimate (at least 8 are used).
    pub k_nearest: u32,
    /// Largest gather radius; 0 picks one from the scene's size.
    pub max_radius: f32,
    pub final_gather: bool,
    pub final_gather_rays: u32,
    /// SPPM: photons traced per pass, starting radius (0 = from the scene's
    /// size) and the radius reduction α.
    pub sppm_photons_per_pass: u32,
    pub sppm_initial_radius: f32,
    pub sppm_alpha: f32,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        Self {
            global_photons: 200_000,
            caustic_photons: 200_000,
            k_nearest: 50,
            max_radius: 0.0,
            final_gather: false,
            final_gather_rays: 32,
            sppm_photons_per_pass: 200_000,
            sppm_initial_radius: 0.0,
            sppm_alpha: 2.0 / 3.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    pub algorithm: Algorithm,
    pub width: u32,
    pub height: u32,
    /// Stop after this many samples per pixel (one per pass); None: no limit.
    pub samples_per_pixel: Option<u32>,
    /// Stop once this many seconds have passed (checked between passes).
    pub time_limit: Option<f64>,
    pub seed: u64,
    /// Worker threads; 0 uses every core.
    pub threads: usize,
    pub max_depth: u32,
    /// Off (0) by default: clamping hides bias. When set, each sample's
    /// channels are limited to this value.
    pub firefly_clamp: f32,
    /// Show one sample per 8×8 block first, so something is on screen at once.
    pub preview: bool,
    pub tile_size: u32,
    pub photon: PhotonSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            algorithm: Algorithm::Path,
            width: 640,
            height: 480,
            samples_per_pixel: None,
            time_limit: None,
            seed: 0,
            threads: 0,
            max_depth: Algorithm::Path.default_max_depth(),
            firefly_clamp: 0.0,
            preview: false,
            tile_size: 32,
            photon: PhotonSettings::default(),
        }
    }
}

impl RenderSettings {
    pub fn for_algorithm(algorithm: Algorithm) -> Self {
        Self { algorithm, max_depth: algorithm.default_max_depth(), ..Self::default() }
    }
}

/// A setting outside its limit: which one, and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct SettingProblem {
    pub field: &'static str,
    pub problem: OutOfRange,
}

impl RenderSettings {
    /// Every setting against `crate::limits`: what the engine refuses to
    /// start, the CLI to accept and the studio to restore.
    pub fn problems(&self) -> Vec<SettingProblem> {
        let mut found = Vec::new();
        let mut check = |field: &'static str, result: Result<(), OutOfRange>| {
            if let Err(problem) = result {
                found.push(SettingProblem { field, problem });
            }
        };
        check("size", limits::check_image_size(self.width, self.height));
        check("samples_per_pixel", self.samples_per_pixel.map_or(Ok(()), |n| ok(limits::SAMPLES_PER_PIXEL.check(n))));
        check("time_limit", self.time_limit.map_or(Ok(()), |t| ok(limits::SECONDS.check(t))));
        check("threads", ok(limits::THREADS.check(self.threads)));
        check("max_depth", ok(limits::MAX_DEPTH.check(self.max_depth)));
        check("firefly_clamp", ok(limits::LENGTH.check(self.firefly_clamp)));
        check("tile_size", ok(limits::TILE_SIZE.check(self.tile_size)));
        let p = &self.photon;
        check("global_photons", ok(limits::PHOTONS.check(p.global_photons)));
        check("caustic_photons", ok(limits::PHOTONS.check(p.caustic_photons)));
        check("k_nearest", ok(limits::K_NEAREST.check(p.k_nearest)));
        check("max_radius", ok(limits::LENGTH.check(p.max_radius)));
        check("final_gather_rays", ok(limits::GATHER_RAYS.check(p.final_gather_rays)));
        check("sppm_photons_per_pass", ok(limits::SPPM_PHOTONS.check(p.sppm_photons_per_pass)));
        check("sppm_initial_radius", ok(limits::LENGTH.check(p.sppm_initial_radius)));
        check("sppm_alpha", ok(limits::SPPM_ALPHA.check(p.sppm_alpha)));
        found
    }
}

fn ok<T>(result: Result<T, OutOfRange>) -> Result<(), OutOfRange> {
    result.map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_within_limits_and_each_bad_value_is_named() {
        for algorithm in Algorithm::ALL {
            assert_eq!(RenderSettings::for_algorithm(algorithm).problems(), vec![], "{algorithm}");
        }
        let bad = RenderSettings {
            width: 100_000,
            threads: 100_000,
            tile_size: 0,
            time_limit: Some(f64::NAN),
            photon: PhotonSettings { k_nearest: u32::MAX, ..PhotonSettings::default() },
            ..RenderSettings::default()
        };
        let fields: Vec<&str> = bad.problems().iter().map(|p| p.field).collect();
        assert_eq!(fields, ["size", "time_limit", "threads", "tile_size", "k_nearest"]);
    }
}
