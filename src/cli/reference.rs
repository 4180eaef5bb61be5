//! `gi-studio reference`: converged references (an EXR with each pixel's
//! variance, metadata beside it), rendered by the method each scene needs,
//! into the reference cache the studio and `bench` read, or into files.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use clap::Args;

use super::outputs::Outputs;
use super::render::{render_with_progress, RenderOutcome};
use super::RenderFlags;
use crate::analysis::reference::{
    info_path, reference_key, reference_method, reference_settings, reference_size, Reference, ReferenceCache,
    ReferenceInfo, REFERENCE_SEED,
};
use crate::fileio::SIGNATURE;
use crate::render::{Algorithm, PassStats, RenderJob, RenderSettings, Workers};
use crate::scene::{load_scene, ValidScene};

#[derive(Debug, Args)]
pub struct ReferenceArgs {
    /// Scene files (RON).
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Output EXR, for a single scene (default: the reference cache).
    #[arg(short, long, conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Write DIR/<scene name>.exr (and .exr.meta.ron) for every scene
    /// (default: the reference cache).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Use this method, not the one the scene needs (path, bdpt, sppm or vcm).
    #[arg(long = "method")]
    pub method: Option<Algorithm>,
    #[command(flatten)]
    pub flags: RenderFlags,
}

/// A rendered reference of `scene` (named `name` in its metadata) as
/// `settings` made it.
pub fn reference_of(scene: &ValidScene, name: &str, settings: &RenderSettings, outcome: RenderOutcome) -> Reference {
    let info = ReferenceInfo {
        scene: name.to_owned(),
        key: reference_key(scene, settings.width, settings.height, settings.algorithm()),
        algorithm: settings.algorithm().name().into(),
        width: settings.width,
        height: settings.height,
        samples_per_pixel: outcome.stats.passes,
        seconds: outcome.stats.elapsed.as_secs_f64(),
        seed: settings.seed,
        program_version: env!("CARGO_PKG_VERSION").into(),
    };
    Reference { image: outcome.image, variance: outcome.variance, info }
}

/// Render the reference of `scene` with `settings` on `workers`, with a
/// progress bar; and the render's statistics.
pub fn render_reference(
    workers: &Workers,
    scene: &Arc<ValidScene>,
    name: &str,
    settings: &RenderSettings,
) -> Result<(Reference, PassStats)> {
    let job = RenderJob { reference: true, ..RenderJob::new(scene.clone(), settings.clone()) };
    let outcome = render_with_progress(workers, job)?;
    let stats = outcome.stats;
    Ok((reference_of(scene, name, settings, outcome), stats))
}

pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.flags.algorithm != Algorithm::Path {
        bail!("references choose their method (see --method); --algo does not apply");
    }
    let converges = |m: &Algorithm| matches!(m, Algorithm::Path | Algorithm::Bdpt | Algorithm::Sppm | Algorithm::Vcm);
    if let Some(method) = args.method.filter(|m| !converges(m)) {
        bail!("--method {method}: references are made by a method that converges everywhere (path, bdpt, sppm, vcm)");
    }
    enum Target {
        Files(Vec<PathBuf>),
        Cache(ReferenceCache),
    }
    let target = match (&args.output, &args.out_dir) {
        (Some(output), None) if args.scenes.len() == 1 => Target::Files(vec![output.clone()]),
        (Some(_), None) => bail!("-o names one file: give one scene, or --out-dir DIR"),
        (None, Some(dir)) => {
            std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
            Target::Files(args.scenes.iter().map(|s| dir.join(format!("{}.exr", stem(s)))).collect())
        }
        _ => Target::Cache(ReferenceCache::open_default().context(
            "there is no cache folder (neither XDG_CACHE_HOME nor HOME is set): give -o FILE.exr or --out-dir DIR",
        )?),
    };
    // Every scene read and every output claimed before the first render: a
    // mistake in any of them writes nothing
    let scenes = args.scenes.iter().map(|path| load_scene(path)).collect::<Result<Vec<_>, _>>()?;
    let mut claims = Outputs::new(args.flags.force);
    args.scenes.iter().for_each(|s| claims.input(s));
    if let Target::Files(outputs) = &target {
        for output in outputs {
            if output.extension().is_none_or(|e| e != "exr") {
                bail!("{}: references are linear EXR files", output.display());
            }
            claims.claim(output, &[SIGNATURE.as_bytes()])?;
            claims.claim(&info_path(output), &[SIGNATURE.as_bytes()])?;
        }
    }
    let workers = args.flags.workers()?;
    for (index, (scene_path, scene)) in args.scenes.iter().zip(scenes).enumerate() {
        let scene = Arc::new(scene);
        let method = reference_method(&scene);
        let algorithm = args.method.unwrap_or(method.algorithm);
        let (width, height) = reference_size(&scene);
        let mut settings = args.flags.settings_as(&scene, algorithm)?;
        (settings.width, settings.height) = (args.flags.width.unwrap_or(width), args.flags.height.unwrap_or(height));
        let defaults = reference_settings(algorithm, settings.width, settings.height);
        if args.flags.spp.is_none() && args.flags.time.is_none() {
            settings.samples_per_pixel = defaults.samples_per_pixel;
        }
        // Never a pane's seed (see REFERENCE_SEED); --seed moves it
        settings.seed = REFERENCE_SEED.wrapping_add(args.flags.seed);
        println!(
            "{}: {}",
            scene_path.display(),
            if args.method.is_some() { "the method asked for" } else { method.reason }
        );
        let (reference, stats) = render_reference(&workers, &scene, &scene_path.display().to_string(), &settings)?;
        let written = match &target {
            Target::Files(outputs) => {
                reference.save(&outputs[index])?;
                outputs[index].clone()
            }
            Target::Cache(cache) => cache.put(&reference)?,
        };
        println!("{}", super::render::summary_line(&settings, &stats, &written.display().to_string()));
    }
    Ok(())
}

pub fn stem(path: &Path) -> String {
    path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}
