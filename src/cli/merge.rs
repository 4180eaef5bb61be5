//! `gi-studio merge`: the partials of a render split by `render --shard`,
//! checked to belong together and joined into one image; and `gi-studio
//! compare`, how far two images are apart.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::outputs::Outputs;
use super::shard::{load_parts, manifest_path, merge};
use crate::analysis::metrics::{rel_mse, rel_mse_against, rmse, RelMseOptions};
use crate::analysis::reference::{info_path, reference_key_of, Reference, ReferenceCache, ReferenceInfo};
use crate::fileio::SIGNATURE;
use crate::render::image::ImageFormat;
use crate::render::{Algorithm, LinearImage};

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Partial EXRs written by `render --shard` (their manifests beside them).
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image: .exr (linear, with each pixel's variance where the
    /// shards kept their halves, and metadata beside it, so it serves as a
    /// reference) or .png (tone-mapped).
    #[arg(short, long, required_unless_present = "reference")]
    pub output: Option<PathBuf>,
    /// Also keep the merged image in the reference cache, where the studio
    /// and `bench` find the reference of its scene.
    #[arg(long)]
    pub reference: bool,
    /// Merge the shards there are, though some are missing.
    #[arg(long)]
    pub partial: bool,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0, value_parser = |s: &str| crate::limits::EXPOSURE_STOPS.parse(s))]
    pub exposure: f32,
    /// Replace an output file that GI Studio did not write.
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let mut outputs = Outputs::new(args.force);
    for part in &args.parts {
        outputs.input(part);
        outputs.input(&manifest_path(part));
    }
    if let Some(output) = &args.output {
        ImageFormat::of(output)?;
        outputs.claim(output, &[SIGNATURE.as_bytes()])?;
        if ImageFormat::of(output)? == ImageFormat::Exr {
            outputs.claim(&info_path(output), &[SIGNATURE.as_bytes()])?;
        }
    }
    let parts = load_parts(&args.parts)?;
    let merged = merge(&parts, !args.partial)?;
    let m = &merged.manifest;
    let Ok(algorithm) = m.algorithm.parse::<Algorithm>() else { bail!("an unknown algorithm \"{}\"", m.algorithm) };
    let scene_key = u64::from_str_radix(&m.scene_key, 16).unwrap_or(0);
    let reference = Reference {
        image: merged.image,
        variance: merged.variance,
        info: ReferenceInfo {
            scene: m.scene.clone(),
            key: reference_key_of(scene_key, m.width, m.height, algorithm),
            algorithm: m.algorithm.clone(),
            width: m.width,
            height: m.height,
            samples_per_pixel: merged.passes,
            seconds: parts.iter().map(|(_, p)| p.manifest.seconds).sum(),
            seed: m.seed,
            program_version: env!("CARGO_PKG_VERSION").into(),
        },
    };
    if let Some(output) = &args.output {
        match ImageFormat::of(output)? {
            ImageFormat::Exr => reference.save(output)?,
            ImageFormat::Png => reference.image.save(output, args.exposure)?,
        }
    }
    if args.reference {
        let cache = ReferenceCache::open_default()
            .ok_or_else(|| anyhow::anyhow!("there is no cache folder (neither XDG_CACHE_HOME nor HOME is set)"))?;
        let path = cache.put(&reference)?;
        println!("kept as the reference of {} in {}", m.scene, path.display());
    }
    let shown = args.output.as_ref().map_or("the reference cache".into(), |o| o.display().to_string());
    println!(
        "merged {} of {} shards of {} ({}, {}×{}): {} samples per pixel; slowest shard {} in {:.2} s → {shown}",
        parts.len(),
        m.shards,
        m.scene,
        m.algorithm,
        m.width,
        m.height,
        merged.passes,
        merged.slowest.0,
        merged.slowest.1
    );
    Ok(())
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The image to measure (EXR or PNG).
    pub image: PathBuf,
    /// What it should be.
    pub reference: PathBuf,
    /// Fail (exit 1) if relMSE exceeds this.
    #[arg(long)]
    pub max_rel_mse: Option<f64>,
}

pub fn compare(args: &CompareArgs) -> Result<()> {
    let (image, reference) = (LinearImage::load(&args.image)?, LinearImage::load(&args.reference)?);
    if (image.width, image.height) != (reference.width, reference.height) {
        bail!(
            "{} is {}×{} and {} is {}×{}",
            args.image.display(),
            image.width,
            image.height,
            args.reference.display(),
            reference.width,
            reference.height
        );
    }
    // A reference made by `gi-studio reference` (its metadata beside it)
    // carries its variance: its own noise is taken off the figure
    let relative = match Reference::load(&args.reference).ok().filter(|r| r.variance.is_some()) {
        Some(stored) => {
            let estimate = rel_mse_against(&image, &stored)?;
            let floor = estimate.noise_floor.unwrap_or(0.0);
            println!("the reference's own noise, taken off: {floor:.3e}");
            estimate.rel_mse
        }
        None => rel_mse(&image, &reference, RelMseOptions::default())?,
    };
    let largest = (image.pixels.iter().flatten())
        .zip(reference.pixels.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    println!("relMSE {relative:.3e}, RMSE {:.3e}, largest difference {largest:.3e}", rmse(&image, &reference)?);
    if let Some(limit) = args.max_rel_mse.filter(|limit| relative > *limit) {
        bail!("relMSE {relative:.3e} is above {limit:.3e}");
    }
    Ok(())
}
