//! A render split over machines: shard I of K renders its share of the
//! passes and writes a partial (an EXR of its mean, and of its odd passes'
//! mean, with a manifest beside it); `merge` checks that the partials
//! belong together and joins them. Where passes are independent samples
//! (every pass's random numbers fixed by (pixel, pass, seed)), shard I takes
//! passes [I·N/K, (I+1)·N/K) and the merge equals the one-process render up
//! to the order of summation. Where each pass builds on the last (SPPM's and
//! VCM's shrinking radius), each shard is a run of its own with its own seed
//! stream, and the merge weighs the runs by their passes.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::fileio::{self, SIGNATURE};
use crate::limits;
use crate::render::layers::{decode_layers, encode_layers};
use crate::render::world::rng::mix64;
use crate::render::{LinearImage, RenderSettings};
use crate::scene::Scene;

/// "I/K": shard I (from 0) of K.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardSpec {
    pub index: u32,
    pub count: u32,
}

impl std::str::FromStr for ShardSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, k) = s.split_once('/').ok_or_else(|| format!("\"{s}\": a shard is I/K, e.g. 0/4"))?;
        let number = |text: &str, what: &str| {
            text.trim().parse::<u32>().map_err(|_| format!("\"{s}\": {what} \"{text}\" is not a whole number"))
        };
        let (index, count) = (number(i, "the shard")?, number(k, "the count")?);
        if count == 0 || count > limits::SHARDS.max {
            return Err(format!("\"{s}\": between 1 and {} shards", limits::SHARDS.max));
        }
        if index >= count {
            return Err(format!("\"{s}\": shards are numbered from 0 to {}", count - 1));
        }
        Ok(ShardSpec { index, count })
    }
}

impl ShardSpec {
    /// The passes of shard `index` of a render of `total`: [first, first + count).
    pub fn passes(&self, total: u32) -> (u32, u32) {
        let at = |i: u32| (i as u64 * total as u64 / self.count as u64) as u32;
        (at(self.index), at(self.index + 1) - at(self.index))
    }

    /// `settings` (a whole render of N passes) as this shard renders it.
    pub fn settings(&self, settings: &RenderSettings) -> Result<RenderSettings> {
        let Some(total) = settings.samples_per_pixel else { bail!("--shard needs --spp: the passes to share") };
        if self.count > total {
            bail!("{} shards of {total} passes: some would have none", self.count);
        }
        let (first, count) = self.passes(total);
        let mut shard = settings.clone();
        shard.samples_per_pixel = Some(count);
        if settings.algorithm().has_independent_passes() {
            shard.first_pass = first;
        } else if self.index > 0 {
            // A run of its own: its own stream of random numbers
            shard.seed = mix64(settings.seed ^ mix64(self.index as u64));
        }
        Ok(shard)
    }
}

/// What a partial says about itself, beside its EXR (`<part>.exr.shard.ron`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardManifest {
    /// The scene file it was rendered from (for messages), and its content.
    pub scene: String,
    pub scene_key: String,
    pub algorithm: String,
    /// Every other setting of the render, as a key.
    pub settings_key: String,
    pub width: u32,
    pub height: u32,
    pub seed: u64,
    pub shard: u32,
    pub shards: u32,
    /// Passes of the whole render, and of this shard from its first.
    pub samples_per_pixel: u32,
    pub first_pass: u32,
    pub passes: u32,
    /// Its passes are samples of one estimate (else a run of its own).
    pub independent: bool,
    pub seconds: f64,
    pub program_version: String,
}

/// `x.exr` → `x.exr.shard.ron`.
pub fn manifest_path(part: &Path) -> PathBuf {
    crate::fileio::beside(part, ".shard.ron")
}

fn header() -> String {
    format!("// {SIGNATURE} shard manifest\n")
}

/// A key of `settings` without what differs between the shards of one render.
fn settings_key(settings: &RenderSettings) -> String {
    let common = RenderSettings { first_pass: 0, samples_per_pixel: None, seed: 0, ..settings.clone() };
    let text = ron::to_string(&common).unwrap_or_default();
    let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    format!("{hash:016x}")
}

impl ShardManifest {
    /// The manifest of shard `spec` of `whole` (the render split), rendered
    /// in `seconds`.
    pub fn new(scene: &Scene, scene_name: &str, whole: &RenderSettings, spec: ShardSpec, seconds: f64) -> Self {
        let total = whole.samples_per_pixel.unwrap_or(0);
        let (first_pass, passes) = spec.passes(total);
        ShardManifest {
            scene: scene_name.to_owned(),
            scene_key: format!("{:016x}", scene.content_key()),
            algorithm: whole.algorithm().name().into(),
            settings_key: settings_key(whole),
            width: whole.width,
            height: whole.height,
            seed: whole.seed,
            shard: spec.index,
            shards: spec.count,
            samples_per_pixel: total,
            first_pass,
            passes,
            independent: whole.algorithm().has_independent_passes(),
            seconds,
            program_version: env!("CARGO_PKG_VERSION").into(),
        }
    }
}

/// A shard's output: its mean, its odd passes' mean (where it keeps
/// halves), its manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct Partial {
    pub mean: LinearImage,
    pub odd: Option<LinearImage>,
    pub manifest: ShardManifest,
}

const ODD: &str = "odd passes";

impl Partial {
    /// Write the EXR and its manifest, each atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let mut layers = vec![("shard mean", &self.mean)];
        layers.extend(self.odd.iter().map(|odd| (ODD, odd)));
        let bytes = encode_layers(&layers).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        fileio::write_bytes(path, &bytes)?;
        let text = ron::ser::to_string_pretty(&self.manifest, ron::ser::PrettyConfig::new())?;
        fileio::write_bytes(&manifest_path(path), (header() + &text + "\n").as_bytes())?;
        Ok(())
    }

    /// Read a partial and its manifest, which must agree on its size.
    pub fn load(path: &Path) -> Result<Self> {
        let max = 2 * limits::IMAGE_PIXELS * 16 + (1 << 20);
        let bytes = fileio::read_bounded(path, max)?;
        let manifest_file = manifest_path(path);
        let text = fileio::read_text(&manifest_file, limits::TEXT_FILE_BYTES)?;
        let manifest: ShardManifest = ron::from_str(&text)
            .map_err(|e| anyhow::anyhow!("{}: line {}: {}", manifest_file.display(), e.span.start.line, e.code))?;
        let mut layers = decode_layers(&bytes).map_err(|e| anyhow::anyhow!("{}: not a shard: {e}", path.display()))?;
        let odd = layers.iter().position(|(name, _)| name == ODD).map(|at| layers.remove(at).1);
        let (_, mean) = layers.swap_remove(0);
        if (mean.width, mean.height) != (manifest.width, manifest.height) {
            bail!(
                "{}: {}×{} pixels where its manifest says {}×{}",
                path.display(),
                mean.width,
                mean.height,
                manifest.width,
                manifest.height
            );
        }
        Ok(Partial { mean, odd, manifest })
    }
}

/// Shards merged: the image, its variance (where every shard kept its odd
/// passes), and what went into it.
pub struct Merged {
    pub image: LinearImage,
    pub variance: Option<LinearImage>,
    pub passes: u32,
    pub manifest: ShardManifest,
    /// The slowest shard: (index, seconds).
    pub slowest: (u32, f64),
}

/// Merge `parts` (each named by its path in errors): they must come from
/// one render (scene, settings, seed, size, shard count), none twice, and,
/// if `complete`, all of them.
pub fn merge(parts: &[(PathBuf, Partial)], complete: bool) -> Result<Merged> {
    let Some((first_path, first)) = parts.first() else { bail!("no shards to merge") };
    let m0 = &first.manifest;
    let mut seen: Vec<Option<&Path>> = vec![None; m0.shards as usize];
    for (path, part) in parts {
        let m = &part.manifest;
        let differs = [
            (m.scene_key != m0.scene_key, "its scene differs"),
            (m.algorithm != m0.algorithm, "its algorithm differs"),
            (m.settings_key != m0.settings_key, "its settings differ"),
            (m.seed != m0.seed, "its seed differs"),
            ((m.width, m.height) != (m0.width, m0.height), "its size differs"),
            (m.shards != m0.shards || m.samples_per_pixel != m0.samples_per_pixel, "it is split otherwise"),
        ]
        .into_iter()
        .find_map(|(differs, what)| differs.then_some(what));
        if let Some(what) = differs {
            bail!(
                "{}: from another render than {} ({what}): shards merge only with their own",
                path.display(),
                first_path.display()
            );
        }
        let spec = ShardSpec { index: m.shard.min(m.shards.saturating_sub(1)), count: m.shards };
        if m.shard >= m.shards || (m.first_pass, m.passes) != spec.passes(m.samples_per_pixel) {
            bail!("{}: its manifest's passes are not shard {}/{}'s", path.display(), m.shard, m.shards);
        }
        if let Some(other) = seen[m.shard as usize].replace(path) {
            bail!("{} and {} are both shard {}/{}", other.display(), path.display(), m.shard, m.shards);
        }
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, p)| p.is_none()).map(|(i, _)| i.to_string()).collect();
    if complete && !missing.is_empty() {
        let (shards, are) = if missing.len() == 1 { ("shard", "is") } else { ("shards", "are") };
        bail!("{shards} {} of {} {are} missing (merge what there is with --partial)", missing.join(", "), m0.shards);
    }
    let passes: u64 = parts.iter().map(|(_, p)| p.manifest.passes as u64).sum();
    let (width, height) = (m0.width, m0.height);
    let mut sum = vec![[0.0f64; 3]; (width * height) as usize];
    let mut odd_sum = vec![[0.0f64; 3]; sum.len()];
    let mut odd_passes = 0u64;
    // A shard of one pass has no odd passes to keep
    let halves = m0.independent && parts.iter().all(|(_, p)| p.odd.is_some() || p.manifest.passes < 2);
    for (_, part) in parts {
        let n = part.manifest.passes as f64;
        let n_odd = (part.manifest.passes / 2) as f64;
        odd_passes += part.manifest.passes as u64 / 2;
        for (i, pixel) in part.mean.pixels.iter().enumerate() {
            for c in 0..3 {
                sum[i][c] += pixel[c] as f64 * n;
            }
        }
        if let Some(odd) = part.odd.as_ref().filter(|_| halves) {
            for (i, pixel) in odd.pixels.iter().enumerate() {
                for c in 0..3 {
                    odd_sum[i][c] += pixel[c] as f64 * n_odd;
                }
            }
        }
    }
    let n = passes as f64;
    let pixels = sum.iter().map(|s| s.map(|c| (c / n) as f32)).collect();
    let image = LinearImage { width, height, pixels };
    // Of n passes, n_o odd and n_e even: the halves' means differ by a
    // quantity of variance σ²(1/n_e + 1/n_o), the mean's is σ²/n
    let even_passes = passes - odd_passes;
    let variance = (halves && odd_passes >= 1 && even_passes >= 1).then(|| {
        let (n_odd, n_even) = (odd_passes as f64, even_passes as f64);
        let scale = n_even * n_odd / (n * n);
        let pixels = (sum.iter().zip(&odd_sum))
            .map(|(s, o)| std::array::from_fn(|c| (((s[c] - o[c]) / n_even - o[c] / n_odd).powi(2) * scale) as f32))
            .collect();
        LinearImage { width, height, pixels }
    });
    let slowest = (parts.iter())
        .map(|(_, p)| (p.manifest.shard, p.manifest.seconds))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0));
    Ok(Merged { image, variance, passes: passes as u32, manifest: m0.clone(), slowest })
}

/// Read every part named, each with its manifest.
pub fn load_parts(paths: &[PathBuf]) -> Result<Vec<(PathBuf, Partial)>> {
    paths.iter().map(|p| Ok((p.clone(), Partial::load(p).with_context(|| "a shard could not be read")?))).collect()
}
