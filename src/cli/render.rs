//! `gi-studio render`: one scene, one algorithm, one image, with a progress bar.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use super::RenderFlags;
use crate::render::{PassStats, RenderEvent, RenderJob, RenderSession, RenderSettings};
use crate::scene::{load_scene, Scene};

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene file (RON), e.g. assets/scenes/cornell.ron.
    pub scene: PathBuf,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear float).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub flags: RenderFlags,
}

impl RenderFlags {
    /// Settings for `scene`, flags overriding the scene's own.
    pub fn settings(&self, scene: &Scene) -> RenderSettings {
        let mut settings = RenderSettings::for_algorithm(self.algorithm);
        settings.width = self.width.unwrap_or(scene.settings.width);
        settings.height = self.height.unwrap_or(scene.settings.height);
        settings.samples_per_pixel = match (self.spp, self.time) {
            (None, None) => Some(64),
            (spp, _) => spp,
        };
        settings.time_limit = self.time;
        settings.seed = self.seed;
        settings.threads = self.threads;
        if let Some(depth) = self.max_depth {
            settings.max_depth = depth;
        }
        settings.firefly_clamp = self.clamp;
        settings
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let extension = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(extension.as_deref(), Some("png" | "exr")) {
        bail!("{}: the output must end in .png or .exr", args.output.display());
    }
    let settings = args.flags.settings(&scene);
    let exposure = args.flags.exposure.unwrap_or(scene.settings.exposure);
    let (image, stats) = render_with_progress(scene, settings.clone())?;
    image.save(&args.output, exposure)?;
    println!("{}", summary_line(&settings, &stats, &args.output.display().to_string()));
    Ok(())
}

/// Render on a session, showing passes (or seconds) on a progress bar.
pub fn render_with_progress(scene: Scene, settings: RenderSettings) -> Result<(crate::render::LinearImage, PassStats)> {
    let bar = match (settings.samples_per_pixel, settings.time_limit) {
        (_, Some(seconds)) => ProgressBar::new((seconds * 10.0).ceil() as u64),
        (Some(spp), None) => ProgressBar::new(spp as u64),
        (None, None) => ProgressBar::new_spinner(),
    };
    let template = "{spinner} {elapsed_precise} [{bar:40}] {msg}";
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()).progress_chars("=> "),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    let timed = settings.time_limit.is_some();
    let session = RenderSession::new(None);
    let generation = session.start(RenderJob::new(Arc::new(scene), settings));
    let result = loop {
        let Ok(event) = session.events().recv() else {
            bail!("the render worker stopped unexpectedly");
        };
        if event.generation() != generation {
            continue;
        }
        match event {
            RenderEvent::PassFinished { stats, .. } => {
                bar.set_position(if timed { (stats.elapsed.as_secs_f64() * 10.0) as u64 } else { stats.passes as u64 });
                bar.set_message(format!("{} spp, {:.2} M samples/s", stats.passes, stats.samples_per_second() / 1e6));
            }
            RenderEvent::Finished { image, stats, .. } => {
                break (Arc::try_unwrap(image).unwrap_or_else(|shared| (*shared).clone()), stats)
            }
            RenderEvent::Failed { message, .. } => bail!("{message}"),
            RenderEvent::Started { .. } | RenderEvent::Tile(_) | RenderEvent::PhotonMaps { .. } => {}
        }
    };
    bar.finish_and_clear();
    Ok(result)
}

pub fn summary_line(settings: &RenderSettings, stats: &PassStats, output: &str) -> String {
    format!(
        "{}×{} {} {} spp in {:.2} s: {:.2} M samples/s, {:.2} M rays/s, {} non-finite samples discarded → {output}",
        settings.width,
        settings.height,
        settings.algorithm,
        stats.passes,
        stats.elapsed.as_secs_f64(),
        stats.samples_per_second() / 1e6,
        stats.rays_per_second() / 1e6,
        stats.non_finite,
    )
}
