//! `gi-studio reference`: converged path-traced references with their
//! metadata beside them (spp, seconds, seed, program version).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use clap::Args;

use super::outputs::Outputs;
use super::render::render_with_progress;
use super::RenderFlags;
use crate::analysis::reference::{info_path, save_info, ReferenceInfo};
use crate::fileio::SIGNATURE;
use crate::render::{Algorithm, RenderJob};
use crate::scene::load_scene;

#[derive(Debug, Args)]
pub struct ReferenceArgs {
    /// Scene files (RON).
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Output EXR, for a single scene.
    #[arg(short, long, conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Write DIR/<scene name>.exr (and .exr.meta.ron) for every scene.
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    #[command(flatten)]
    pub flags: RenderFlags,
}

pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.flags.algorithm != Algorithm::Path {
        bail!("references are path traced (--algo path)");
    }
    let outputs: Vec<PathBuf> = match (&args.output, &args.out_dir) {
        (Some(output), None) if args.scenes.len() == 1 => vec![output.clone()],
        (None, Some(dir)) => {
            std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
            args.scenes.iter().map(|s| dir.join(format!("{}.exr", stem(s)))).collect()
        }
        _ => bail!("give -o FILE.exr for one scene, or --out-dir DIR"),
    };
    // Every scene read and every output claimed before the first render: a
    // mistake in any of them writes nothing
    let scenes = args.scenes.iter().map(|path| load_scene(path)).collect::<Result<Vec<_>, _>>()?;
    let mut claims = Outputs::new(args.flags.force);
    args.scenes.iter().for_each(|s| claims.input(s));
    for output in &outputs {
        if output.extension().is_none_or(|e| e != "exr") {
            bail!("{}: references are linear EXR files", output.display());
        }
        claims.claim(output, &[SIGNATURE.as_bytes()])?;
        claims.claim(&info_path(output), &[SIGNATURE.as_bytes()])?;
    }
    for ((scene_path, scene), output) in args.scenes.iter().zip(scenes).zip(outputs) {
        let mut settings = args.flags.settings(&scene)?;
        // Half the scene's size by default: the studio's four-pane size
        settings.width = args.flags.width.unwrap_or((scene.settings.width / 2).max(1));
        settings.height = args.flags.height.unwrap_or((scene.settings.height / 2).max(1));
        if args.flags.spp.is_none() && args.flags.time.is_none() {
            settings.samples_per_pixel = Some(4096);
        }
        let outcome = render_with_progress(RenderJob::new(Arc::new(scene), settings.clone()))?;
        outcome.image.save(&output, 0.0)?;
        let info = ReferenceInfo {
            scene: scene_path.display().to_string(),
            algorithm: settings.algorithm().name().into(),
            width: settings.width,
            height: settings.height,
            samples_per_pixel: outcome.stats.passes,
            seconds: outcome.stats.elapsed.as_secs_f64(),
            seed: settings.seed,
            program_version: env!("CARGO_PKG_VERSION").into(),
        };
        save_info(&info, &output)?;
        println!("{}", super::render::summary_line(&settings, &outcome.stats, &output.display().to_string()));
    }
    Ok(())
}

pub fn stem(path: &Path) -> String {
    path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}
