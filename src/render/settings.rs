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
    LightTracing,
    Bdpt,
    Bpm,
    Vcm,
}

impl Algorithm {
    pub const ALL: [Algorithm; 8] = [
        Algorithm::Whitted,
        Algorithm::Path,
        Algorithm::Photon,
        Algorithm::Sppm,
        Algorithm::LightTracing,
        Algorithm::Bdpt,
        Algorithm::Bpm,
        Algorithm::Vcm,
    ];

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Whitted => "whitted",
            Algorithm::Path => "path",
            Algorithm::Photon => "photon",
            Algorithm::Sppm => "sppm",
            Algorithm::LightTracing => "lt",
            Algorithm::Bdpt => "bdpt",
            Algorithm::Bpm => "bpm",
            Algorithm::Vcm => "vcm",
        }
    }

    /// Whether it traces paths from the lights too: only such a method
    /// sees a point light through glass (`unseen`).
    pub fn traces_from_lights(self) -> bool {
        !matches!(self, Algorithm::Whitted | Algorithm::Path)
    }

    pub fn label(self) -> &'static str {
        match self {
            Algorithm::Whitted => "Whitted ray tracing",
            Algorithm::Path => "Path tracing",
            Algorithm::Photon => "Photon mapping",
            Algorithm::Sppm => "Progressive photon mapping",
            Algorithm::LightTracing => "Light tracing",
            Algorithm::Bdpt => "Bidirectional path tracing",
            Algorithm::Bpm => "Bidirectional photon mapping",
            Algorithm::Vcm => "Vertex connection and merging",
        }
    }

    /// Whether its passes are independent samples of the same estimate, so
    /// a render splits into ranges of passes (shards) that merge exactly;
    /// otherwise each pass builds on the ones before (a shrinking radius)
    /// and shards are independent runs, merged by weighting.
    pub fn has_independent_passes(self) -> bool {
        !matches!(self, Algorithm::Sppm | Algorithm::Bpm | Algorithm::Vcm)
    }

    /// Whether it traces paths from both ends (one strategy set of
    /// `integrators::bidir`): its tiles are final only once the light
    /// paths' splats are in, at the end of a pass.
    pub fn is_bidirectional(self) -> bool {
        matches!(self, Algorithm::LightTracing | Algorithm::Bdpt | Algorithm::Bpm | Algorithm::Vcm)
    }

    /// Whether its passes are independent unbiased estimates of the
    /// converged image: then the spread between them is its error, and the
    /// film keeps its odd passes apart to measure it.
    pub fn is_unbiased(self) -> bool {
        matches!(self, Algorithm::Path | Algorithm::LightTracing | Algorithm::Bdpt)
    }

    /// The longest path each draws by default (`RenderSettings::max_depth`):
    /// the thesis' five rays for Whitted, with its shadow ray six segments;
    /// the Monte Carlo methods end paths by Russian roulette well before
    /// their cap.
    pub fn default_max_depth(self) -> u32 {
        match self {
            Algorithm::Whitted => 6,
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
        Algorithm::ALL.into_iter().find(|a| a.name().eq_ignore_ascii_case(s)).ok_or_else(|| {
            let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
            format!("unknown algorithm \"{s}\" (expected {})", names.join(", "))
        })
    }
}

/// An algorithm with the knobs that apply to it, and no others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Method {
    Whitted,
    Path,
    Photon(PhotonSettings),
    Sppm(SppmSettings),
    LightTracing,
    Bdpt(BidirSettings),
    Bpm(MergeSettings),
    Vcm(MergeSettings),
}

impl Method {
    pub fn algorithm(&self) -> Algorithm {
        match self {
            Method::Whitted => Algorithm::Whitted,
            Method::Path => Algorithm::Path,
            Method::Photon(_) => Algorithm::Photon,
            Method::Sppm(_) => Algorithm::Sppm,
            Method::LightTracing => Algorithm::LightTracing,
            Method::Bdpt(_) => Algorithm::Bdpt,
            Method::Bpm(_) => Algorithm::Bpm,
            Method::Vcm(_) => Algorithm::Vcm,
        }
    }

    /// `algorithm` with its default knobs.
    pub fn of(algorithm: Algorithm) -> Self {
        match algorithm {
            Algorithm::Whitted => Method::Whitted,
            Algorithm::Path => Method::Path,
            Algorithm::Photon => Method::Photon(PhotonSettings::default()),
            Algorithm::Sppm => Method::Sppm(SppmSettings::default()),
            Algorithm::LightTracing => Method::LightTracing,
            Algorithm::Bdpt => Method::Bdpt(BidirSettings::default()),
            Algorithm::Bpm => Method::Bpm(MergeSettings::default()),
            Algorithm::Vcm => Method::Vcm(MergeSettings { caustic_merges: true, ..MergeSettings::default() }),
        }
    }
}

/// How bidirectional methods weigh their strategies against each other
/// (multiple importance sampling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MisHeuristic {
    /// Veach's power heuristic, β = 2: less noise where one strategy is
    /// much better than the rest.
    #[default]
    Power,
    /// The balance heuristic, β = 1.
    Balance,
}

impl MisHeuristic {
    pub fn name(self) -> &'static str {
        match self {
            MisHeuristic::Power => "power",
            MisHeuristic::Balance => "balance",
        }
    }
}

impl FromStr for MisHeuristic {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "power" => Ok(MisHeuristic::Power),
            "balance" => Ok(MisHeuristic::Balance),
            _ => Err(format!("unknown heuristic \"{s}\" (expected power or balance)")),
        }
    }
}

/// Bidirectional path tracing: every connection of a light subpath to a
/// camera subpath, weighed by `mis`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BidirSettings {
    pub mis: MisHeuristic,
}

/// Vertex merging (bidirectional photon mapping, and VCM's merges): the
/// merge radius at the first pass (0: 2% of what the camera sees for BPM,
/// 1% for VCM merging on caustic paths, 0.5% for VCM merging everywhere),
/// which shrinks as pass^−(1−α)/2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MergeSettings {
    pub mis: MisHeuristic,
    pub radius: f32,
    pub alpha: f32,
    /// VCM only: merge only where light came through a mirror or glass
    /// (caustic paths), leaving every other path to the connections. On
    /// for a new VCM (`Method::of`): on every preset it reaches an error
    /// sooner than merging everywhere, as Georgiev et al. 2012 do (which a
    /// saved VCM without this field keeps).
    pub caustic_merges: bool,
}

impl Default for MergeSettings {
    fn default() -> Self {
        Self { mis: MisHeuristic::Power, radius: 0.0, alpha: 0.75, caustic_merges: false }
    }
}

/// Jensen's photon mapping: two maps and their estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PhotonSettings {
    pub global_photons: u32,
    pub caustic_photons: u32,
    /// Photons gathered per radiance estimate.
    pub k_nearest: u32,
    /// Largest gather radius; 0 picks one from the scene's size.
    pub max_radius: f32,
    pub final_gather: bool,
    pub final_gather_rays: u32,
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
        }
    }
}

/// Progressive photon mapping: photons per pass, the starting radius (0 =
/// from the scene's size) and the radius reduction α.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SppmSettings {
    pub photons_per_pass: u32,
    pub initial_radius: f32,
    pub alpha: f32,
}

impl Default for SppmSettings {
    fn default() -> Self {
        Self { photons_per_pass: 200_000, initial_radius: 0.0, alpha: 2.0 / 3.0 }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    pub method: Method,
    pub width: u32,
    pub height: u32,
    /// Stop after this many samples per pixel (one per pass); None: no limit.
    pub samples_per_pixel: Option<u32>,
    /// The index of the first pass: a shard of a render starts where the
    /// ones before it end (`cli::shard`), so its samples are theirs.
    pub first_pass: u32,
    /// Stop once this many seconds have passed (checked between passes).
    pub time_limit: Option<f64>,
    pub seed: u64,
    /// The longest path, in segments from the camera to a light, for every
    /// algorithm: 1 sees the lights, 2 adds their direct light, each more one
    /// more bounce. (Whitted always shades what the camera sees. Photon
    /// mapping's and SPPM's photons fly at most `max_depth` − 1 segments, not
    /// knowing how far the camera came: through mirrors or glass, the paths
    /// they gather can be longer.)
    pub max_depth: u32,
    /// Off (0) by default: clamping hides bias. When set, each sample's
    /// channels are limited to this value.
    pub firefly_clamp: f32,
    /// Show one sample per 8×8 block first, so something is on screen at once.
    pub preview: bool,
    pub tile_size: u32,
}

/// What `RenderSettings::max_depth` means, as the CLI's help and the
/// studio's tooltip say it.
pub const DEPTH_MEANING: &str = "The longest path, in segments from the camera to a light, for every \
    algorithm: 1 sees the lights, 2 adds their direct light, each more one more bounce";

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            method: Method::Path,
            width: 640,
            height: 480,
            samples_per_pixel: None,
            first_pass: 0,
            time_limit: None,
            seed: 0,
            max_depth: Algorithm::Path.default_max_depth(),
            firefly_clamp: 0.0,
            preview: false,
            tile_size: 32,
        }
    }
}

impl RenderSettings {
    pub fn for_algorithm(algorithm: Algorithm) -> Self {
        Self { method: Method::of(algorithm), max_depth: algorithm.default_max_depth(), ..Self::default() }
    }

    pub fn algorithm(&self) -> Algorithm {
        self.method.algorithm()
    }

    /// `count` photons for each map (photon mapping) or each pass (SPPM);
    /// the other methods trace none.
    pub fn set_photons(&mut self, count: u32) {
        match &mut self.method {
            Method::Photon(p) => (p.global_photons, p.caustic_photons) = (count, count),
            Method::Sppm(p) => p.photons_per_pass = count,
            _ => {}
        }
    }

    /// Photon mapping's knobs, when that is the method.
    pub fn photon(&self) -> Option<&PhotonSettings> {
        match &self.method {
            Method::Photon(p) => Some(p),
            _ => None,
        }
    }

    /// Photon mapping's knobs, when that is the method.
    pub fn photon_mut(&mut self) -> Option<&mut PhotonSettings> {
        match &mut self.method {
            Method::Photon(p) => Some(p),
            _ => None,
        }
    }

    /// SPPM's knobs, when that is the method.
    pub fn sppm_mut(&mut self) -> Option<&mut SppmSettings> {
        match &mut self.method {
            Method::Sppm(p) => Some(p),
            _ => None,
        }
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
        check("first_pass", ok(limits::SAMPLES_PER_PIXEL.check(self.first_pass.max(1))));
        check("time_limit", self.time_limit.map_or(Ok(()), |t| ok(limits::SECONDS.check(t))));
        check("max_depth", ok(limits::MAX_DEPTH.check(self.max_depth)));
        check("firefly_clamp", ok(limits::LENGTH.check(self.firefly_clamp)));
        check("tile_size", ok(limits::TILE_SIZE.check(self.tile_size)));
        match &self.method {
            Method::Whitted | Method::Path | Method::LightTracing | Method::Bdpt(_) => {}
            Method::Bpm(m) | Method::Vcm(m) => {
                check("merge radius", ok(limits::LENGTH.check(m.radius)));
                check("merge alpha", ok(limits::SPPM_ALPHA.check(m.alpha)));
            }
            Method::Photon(p) => {
                check("global_photons", ok(limits::PHOTONS.check(p.global_photons)));
                check("caustic_photons", ok(limits::PHOTONS.check(p.caustic_photons)));
                check("k_nearest", ok(limits::K_NEAREST.check(p.k_nearest)));
                check("max_radius", ok(limits::LENGTH.check(p.max_radius)));
                check("final_gather_rays", ok(limits::GATHER_RAYS.check(p.final_gather_rays)));
            }
            Method::Sppm(p) => {
                check("photons_per_pass", ok(limits::SPPM_PHOTONS.check(p.photons_per_pass)));
                check("initial_radius", ok(limits::LENGTH.check(p.initial_radius)));
                check("alpha", ok(limits::SPPM_ALPHA.check(p.alpha)));
            }
        }
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
            tile_size: 0,
            time_limit: Some(f64::NAN),
            method: Method::Photon(PhotonSettings { k_nearest: u32::MAX, ..PhotonSettings::default() }),
            ..RenderSettings::default()
        };
        let fields: Vec<&str> = bad.problems().iter().map(|p| p.field).collect();
        assert_eq!(fields, ["size", "time_limit", "tile_size", "k_nearest"]);
    }
}
