//! `gi-studio render`: one scene, one algorithm, one image, with a progress bar.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use super::outputs::Outputs;
use super::shard::{manifest_path, Partial, ShardManifest, ShardSpec};
use super::RenderFlags;
use crate::fileio::SIGNATURE;
use crate::render::image::ImageFormat;
use crate::render::integrators::photon_map::file::{load_photon_maps, settings_key};
use crate::render::integrators::photon_map::maps::MapStats;
use crate::render::integrators::photon_map::PhotonMapStats;
use crate::render::unseen::unseen_lights;
use crate::render::{
    Algorithm, LinearImage, Method, PassStats, RenderEvent, RenderJob, RenderSession, RenderSettings, Workers,
};
use crate::scene::{load_scene, Scene};

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene file (RON), e.g. assets/scenes/cornell.ron.
    pub scene: PathBuf,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear float).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Reuse photon maps saved by `gi-studio photons` (photon mapping only).
    #[arg(long)]
    pub photon_map: Option<PathBuf>,
    /// Render shard I of K of the --spp passes, e.g. 0/4, into a partial
    /// EXR (with its manifest beside it) for `gi-studio merge`. Whitted,
    /// path, photon, lt and bdpt take passes [I·N/K, (I+1)·N/K) of one
    /// render (merged exactly); sppm, bpm and vcm, whose passes build on
    /// each other, run N/K passes of their own with a seed of their own
    /// (merged by weighting).
    #[arg(long)]
    pub shard: Option<ShardSpec>,
    #[command(flatten)]
    pub flags: RenderFlags,
}

/// What a finished render reports besides its image.
pub struct RenderOutcome {
    pub image: crate::render::LinearImage,
    /// Each pixel's estimated variance (unbiased methods).
    pub variance: Option<crate::render::LinearImage>,
    /// The odd passes' mean alone (where there is a variance).
    pub odd: Option<crate::render::LinearImage>,
    pub stats: PassStats,
    pub maps: Option<PhotonMapStats>,
    /// SPPM's mean gather radius after each pass.
    pub radii: Vec<f32>,
}

impl RenderFlags {
    /// The render threads `--threads` asks for.
    pub fn workers(&self) -> Result<Workers> {
        Workers::new(self.threads).with_context(|| format!("could not start {} render threads", self.threads))
    }

    /// Settings for `scene`, flags overriding the scene's own.
    pub fn settings(&self, scene: &Scene) -> Result<RenderSettings> {
        self.settings_as(scene, self.algorithm)
    }

    /// Settings for `scene` with `algorithm` (whatever `--algo` says).
    pub fn settings_as(&self, scene: &Scene, algorithm: Algorithm) -> Result<RenderSettings> {
        let mut settings = RenderSettings::for_algorithm(algorithm);
        settings.method = self.method(algorithm)?;
        settings.width = self.width.unwrap_or(scene.settings.width);
        settings.height = self.height.unwrap_or(scene.settings.height);
        settings.samples_per_pixel = match (self.spp, self.time) {
            (None, None) => Some(64),
            (spp, _) => spp,
        };
        settings.time_limit = self.time;
        settings.seed = self.seed;
        if let Some(depth) = self.max_depth {
            settings.max_depth = depth;
        }
        settings.firefly_clamp = self.clamp;
        // Each flag was checked as it was parsed; what is left is the image
        // size they make together with the scene's
        if let Some(problem) = settings.problems().into_iter().next() {
            bail!("{problem}");
        }
        Ok(settings)
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    ImageFormat::of(&args.output)?;
    let mut outputs = Outputs::new(args.flags.force);
    outputs.input(&args.scene);
    if let Some(path) = &args.photon_map {
        outputs.input(path);
    }
    outputs.claim(&args.output, &[SIGNATURE.as_bytes()])?;
    let settings = args.flags.settings(&scene)?;
    let exposure = args.flags.exposure.unwrap_or(scene.settings.exposure);
    for line in unseen_lights(&scene, settings.algorithm()) {
        eprintln!("warning: {line}");
    }
    let mut job = RenderJob::new(Arc::new(scene), settings.clone());
    if let Some(path) = &args.photon_map {
        let Method::Photon(photon) = &settings.method else {
            bail!("--photon-map is for --algo photon");
        };
        let keys = (job.scene.content_key(), settings_key(photon, settings.seed, settings.max_depth));
        job.photon_maps = Some(Arc::new(load_photon_maps(path, keys.0, keys.1)?));
    }
    if let Some(spec) = args.shard {
        return render_shard(args, spec, job);
    }
    let outcome = render_with_progress(&args.flags.workers()?, job)?;
    outcome.image.save(&args.output, exposure)?;
    println!("{}", summary_line(&settings, &outcome.stats, &args.output.display().to_string()));
    print_photon_statistics(&outcome);
    if let Some(line) = paths_line(&outcome.stats) {
        println!("{line}");
    }
    Ok(())
}

/// Render shard `spec` of `job`'s render into a partial at `args.output`.
fn render_shard(args: &RenderArgs, spec: ShardSpec, mut job: RenderJob) -> Result<()> {
    if args.output.extension().is_none_or(|e| e != "exr") {
        bail!("{}: a shard is a partial EXR (for gi-studio merge)", args.output.display());
    }
    let mut outputs = Outputs::new(args.flags.force);
    outputs.input(&args.scene);
    outputs.claim(&manifest_path(&args.output), &[SIGNATURE.as_bytes()])?;
    let whole = job.settings.clone();
    job.settings = spec.settings(&whole)?;
    let scene = job.scene.clone();
    let outcome = render_with_progress(&args.flags.workers()?, job)?;
    let seconds = outcome.stats.elapsed.as_secs_f64();
    let manifest = ShardManifest::new(&scene, &args.scene.display().to_string(), &whole, spec, seconds);
    let passes = (manifest.first_pass, manifest.first_pass + manifest.passes);
    Partial { mean: outcome.image, odd: outcome.odd, manifest }.save(&args.output)?;
    println!(
        "shard {}/{}: passes {}..{} of {} in {seconds:.2} s → {}",
        spec.index,
        spec.count,
        passes.0,
        passes.1,
        whole.samples_per_pixel.unwrap_or(0),
        args.output.display()
    );
    Ok(())
}

/// The bidirectional methods' last pass, per light path and per pixel.
pub fn paths_line(stats: &PassStats) -> Option<String> {
    let p = &stats.paths;
    if p.light_paths == 0 {
        return None;
    }
    let per = |n: u64| n as f64 / p.light_paths as f64;
    let radius = if p.merge_radius > 0.0 { format!(", merge radius {:.4}", p.merge_radius) } else { String::new() };
    Some(format!(
        "last pass: {} light paths of {:.2} stored vertices each; per pixel {:.2} connections, {:.2} merges{radius}",
        p.light_paths,
        per(p.light_vertices),
        per(p.connections),
        per(p.merges)
    ))
}

pub fn print_photon_statistics(outcome: &RenderOutcome) {
    if let Some(maps) = &outcome.maps {
        for (name, map) in [("global", &maps.global), ("caustic", &maps.caustic)] {
            println!("{}", map_line(name, map));
        }
    }
    let q = &outcome.stats.photon.queries;
    if q.queries > 0 {
        let total: u64 = q.radius_histogram.iter().sum();
        let histogram: Vec<String> =
            q.radius_histogram.iter().map(|n| format!("{:.0}", 100.0 * *n as f64 / total.max(1) as f64)).collect();
        println!(
            "k-NN (last pass): {} queries, {:.1} nodes visited and {:.2} µs per query; gather radius / max radius, % per sixteenth: [{}]",
            q.queries,
            q.mean_nodes_visited(),
            q.mean_query_time().as_secs_f64() * 1e6,
            histogram.join(" ")
        );
    }
    if !outcome.radii.is_empty() {
        // Passes 1, 2, 4, 8, … and the last: the whole curve in one line
        let count = outcome.radii.len();
        let shown: Vec<String> = (0..)
            .map(|k| 1usize << k)
            .take_while(|pass| *pass < count)
            .chain(std::iter::once(count))
            .map(|pass| format!("{pass}: {:.4}", outcome.radii[pass - 1]))
            .collect();
        let photon = &outcome.stats.photon;
        println!(
            "SPPM mean radius per pass [{}]; last pass traced {} photons ({} stored)",
            shown.join(", "),
            photon.photons_traced,
            photon.photons_stored,
        );
        println!("SPPM last pass: {}", photon.times.summary());
    }
}

pub fn map_line(name: &str, map: &MapStats) -> String {
    format!(
        "{name} map: {} emitted, {} stored ({:.1} MB), traced in {:.0} ms, built in {:.0} ms, tree depth {}",
        map.emitted,
        map.stored,
        map.bytes as f64 / 1e6,
        map.trace_time.as_secs_f64() * 1e3,
        map.build_time.as_secs_f64() * 1e3,
        map.depth
    )
}

/// Render on a session on `workers`, showing passes (or seconds) on a
/// progress bar.
pub fn render_with_progress(workers: &Workers, job: RenderJob) -> Result<RenderOutcome> {
    // Only the final image is written
    let job = RenderJob { stream_tiles: false, ..job };
    let settings = job.settings.clone();
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
    let session = RenderSession::new(workers, None).context("could not start the render worker")?;
    let generation = session.start(job);
    let mut maps = None;
    let mut radii = Vec::new();
    let result = loop {
        let Ok(event) = session.events().recv() else {
            bail!("the render worker stopped unexpectedly");
        };
        if event.generation() != generation {
            continue;
        }
        match event {
            RenderEvent::PhotonMaps { stats, .. } => {
                maps = Some(stats);
                bar.set_message("photon maps built");
            }
            RenderEvent::PassFinished { stats, .. } => {
                if settings.algorithm() == Algorithm::Sppm {
                    radii.push(stats.photon.mean_radius);
                }
                bar.set_position(if timed { (stats.elapsed.as_secs_f64() * 10.0) as u64 } else { stats.passes as u64 });
                bar.set_message(format!("{} spp, {:.2} M samples/s", stats.passes, stats.samples_per_second() / 1e6));
            }
            RenderEvent::Finished { image, variance, odd, stats, .. } => {
                let owned = |shared: Arc<LinearImage>| Arc::try_unwrap(shared).unwrap_or_else(|s| (*s).clone());
                let (image, variance, odd) = (owned(image), variance.map(owned), odd.map(owned));
                break RenderOutcome { image, variance, odd, stats, maps, radii };
            }
            RenderEvent::Failed { message, .. } => bail!("{message}"),
            RenderEvent::Started { .. } | RenderEvent::Tile(_) | RenderEvent::Strategies { .. } => {}
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
        settings.algorithm(),
        stats.passes,
        stats.elapsed.as_secs_f64(),
        stats.samples_per_second() / 1e6,
        stats.rays_per_second() / 1e6,
        stats.non_finite,
    )
}
