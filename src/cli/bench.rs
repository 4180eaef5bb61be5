//! `gi-studio bench`: speed against error. Every algorithm renders every
//! scene for the same wall-clock budget; after each pass the image is
//! compared with the scene's converged reference. Prints a table and writes
//! a CSV, a log–log plot and the final images.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use super::merges::Merges;
use super::outputs::Outputs;
use super::reference::{render_reference, stem};
use crate::analysis::convergence::{ConvergenceLog, ConvergencePoint};
use crate::analysis::metrics::{flip, rel_mse_against};
use crate::analysis::plot::plot_error_against_time;
use crate::analysis::reference::{
    find, reference_method, reference_settings, reference_size, Reference, ReferenceCache,
};
use crate::fileio::{self, SIGNATURE};
use crate::limits;
use crate::render::unseen::unseen_lights;
use crate::render::{
    Algorithm, LinearImage, Method, PassStats, RenderEvent, RenderJob, RenderSession, RenderSettings, Workers,
};
use crate::scene::{load_scene, presets, ValidScene};

#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Scene files; every preset if none.
    pub scenes: Vec<PathBuf>,
    /// Seconds each algorithm renders each scene.
    #[arg(long, default_value_t = 10.0, value_parser = |s: &str| limits::SECONDS.parse(s))]
    pub budget: f64,
    /// Comma-separated algorithms.
    #[arg(long, value_delimiter = ',', default_value = "whitted,path,photon,sppm,lt,bdpt,bpm,vcm")]
    pub algos: Vec<Algorithm>,
    /// A folder of references named <scene>.exr to use instead of the
    /// built-in ones and the reference cache.
    #[arg(long)]
    pub references: Option<PathBuf>,
    /// For a scene without a reference, render one for up to this many
    /// seconds first (and keep it in the cache); 0: refuse such a scene.
    #[arg(long, default_value_t = 120.0, value_parser = |s: &str| limits::SECONDS_OR_NONE.parse(s))]
    pub reference_budget: f64,
    /// Where the CSV, plots and final images go.
    #[arg(long, default_value = "bench-results")]
    pub out: PathBuf,
    #[arg(long, default_value_t = 0, value_parser = |s: &str| limits::THREADS.parse(s))]
    pub threads: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Replace output files that GI Studio did not write.
    #[arg(long)]
    pub force: bool,
    /// Where VCM merges: caustics or everywhere [default: caustics].
    #[arg(long, value_enum)]
    pub merges: Option<Merges>,
}

/// The CSV's first line, which also marks the file as this program's.
const CSV_HEADER: &str = "scene,algorithm,seconds,spp,rays,relmse,relmse_se,flip\n";

/// One algorithm on one scene.
pub struct Run {
    pub algorithm: Algorithm,
    pub log: ConvergenceLog,
    pub stats: PassStats,
    pub image: LinearImage,
}

/// Images kept for FLIP until the render ends, at most this many bytes:
/// FLIP measured between passes would take the CPU from the render it
/// times (its thread runs above the workers), most of all early on, where
/// the table's times to an error are read. Past the bound (huge images over a
/// long budget) FLIP is measured at once again.
const FLIP_KEPT_BYTES: usize = 256 << 20;

/// Render `scene` with `settings` on `workers` until its budget, logging
/// error against `reference` after every pass (FLIP at roughly log-spaced
/// times, measured once the render has ended).
pub fn measure(
    workers: &Workers,
    scene: &Arc<ValidScene>,
    settings: RenderSettings,
    reference: &Reference,
    progress: Option<&ProgressBar>,
) -> Result<Run> {
    let session = RenderSession::new(workers, None).context("could not start the render worker")?;
    let (width, height) = (settings.width, settings.height);
    let algorithm = settings.algorithm();
    let generation = session.start(RenderJob::new(scene.clone(), settings));
    let mut image = LinearImage::new(width, height);
    let mut log = ConvergenceLog::default();
    let mut next_flip = 0.0;
    // (point, image at that point) for FLIP after the render
    let mut for_flip: Vec<(usize, LinearImage)> = Vec::new();
    let image_bytes = std::mem::size_of_val(image.pixels.as_slice());
    loop {
        let event = session.events().recv().context("the render worker stopped")?;
        if event.generation() != generation {
            continue;
        }
        match event {
            RenderEvent::Tile(tile) if !tile.preview => {
                let rect = tile.rect;
                for (i, pixel) in tile.pixels.into_iter().enumerate() {
                    let (x, y) = (rect.x + i as u32 % rect.width, rect.y + i as u32 / rect.width);
                    image.pixels[(y * width + x) as usize] = pixel;
                }
            }
            RenderEvent::PassFinished { stats, .. } => {
                let seconds = stats.elapsed.as_secs_f64();
                let mut flip_now = None;
                if seconds >= next_flip {
                    next_flip = seconds * 1.5;
                    if (for_flip.len() + 1) * image_bytes <= FLIP_KEPT_BYTES {
                        for_flip.push((log.points.len(), image.clone()));
                    } else {
                        flip_now = Some(flip(&image, &reference.image, 0.0)?);
                    }
                }
                log.push(ConvergencePoint {
                    seconds,
                    samples_per_pixel: stats.passes,
                    rays: stats.rays,
                    error: rel_mse_against(&image, reference)?,
                    flip: flip_now,
                });
                if let Some(bar) = progress {
                    bar.set_position((seconds * 10.0) as u64);
                }
            }
            RenderEvent::Finished { image: last, stats, .. } => {
                let image = Arc::try_unwrap(last).unwrap_or_else(|shared| (*shared).clone());
                for (point, kept) in &for_flip {
                    log.points[*point].flip = Some(flip(kept, &reference.image, 0.0)?);
                }
                if let Some(point) = log.points.last_mut() {
                    point.flip = Some(flip(&image, &reference.image, 0.0)?);
                }
                return Ok(Run { algorithm, log, stats, image });
            }
            RenderEvent::Failed { message, .. } => bail!("{algorithm}: {message}"),
            _ => {}
        }
    }
}

fn format_time(t: Option<f64>) -> String {
    t.map_or("—".into(), |t| format!("{t:.2} s"))
}

fn format_error(e: Option<f64>) -> String {
    e.map_or("—".into(), |e| format!("{e:.2e}"))
}

/// A scene to measure: its name, the scene, where it came from.
struct Subject {
    name: String,
    scene: Arc<ValidScene>,
    file: Option<PathBuf>,
}

/// The reference `subject` is measured against, and where it came from:
/// `--references`, the built-in ones and the cache, or rendered now.
fn reference_for(args: &BenchArgs, subject: &Subject, workers: &Workers) -> Result<(Reference, String)> {
    let scene = &subject.scene;
    if let Some(dir) = &args.references {
        let path = dir.join(format!("{}.exr", subject.name));
        let reference = Reference::load(&path).with_context(|| format!("the reference for {}", subject.name))?;
        return Ok((reference, path.display().to_string()));
    }
    let (width, height) = reference_size(scene);
    let cache = ReferenceCache::open_default();
    if let Some(reference) = find(scene, width, height, cache.as_ref()) {
        let made = format!("{}, {} spp", reference.info.algorithm, reference.info.samples_per_pixel);
        return Ok((reference, made));
    }
    let method = reference_method(scene);
    let file = subject.file.as_ref().map_or_else(|| subject.name.clone(), |f| f.display().to_string());
    if args.reference_budget <= 0.0 {
        bail!(
            "no reference for {file}: make one with `gi-studio reference {file}`, or give --reference-budget SECONDS"
        );
    }
    println!(
        "{}: no reference yet; rendering one for up to {} s ({})",
        subject.name, args.reference_budget, method.reason
    );
    let mut settings = reference_settings(method.algorithm, width, height);
    settings.time_limit = Some(args.reference_budget);
    let (reference, stats) = render_reference(workers, scene, &file, &settings)?;
    let kept = match &cache {
        Some(cache) => cache.put(&reference).map(|p| format!(", kept in {}", p.display()))?,
        None => String::new(),
    };
    let made = format!("{}, {} spp in {:.0} s{kept}", method.algorithm, stats.passes, stats.elapsed.as_secs_f64());
    Ok((reference, made))
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let subjects: Vec<Subject> = if args.scenes.is_empty() {
        (presets::names())
            .map(|name| {
                let scene = presets::preset(name).context("a preset")??;
                Ok(Subject { name: name.to_owned(), scene: Arc::new(scene), file: None })
            })
            .collect::<Result<_>>()?
    } else {
        (args.scenes.iter())
            .map(|path| Ok(Subject { name: stem(path), scene: Arc::new(load_scene(path)?), file: Some(path.clone()) }))
            .collect::<Result<_>>()?
    };
    // Every scene read and every output claimed before any work
    let mut outputs = Outputs::new(args.force);
    let sign: &[&[u8]] = &[SIGNATURE.as_bytes()];
    for subject in &subjects {
        if let Some(file) = &subject.file {
            outputs.input(file);
        }
        if let Some(dir) = &args.references {
            outputs.input(&dir.join(format!("{}.exr", subject.name)));
        }
        for algorithm in &args.algos {
            outputs.claim(&args.out.join(format!("{}-{algorithm}.png", subject.name)), sign)?;
        }
        outputs.claim(&args.out.join(format!("{}.png", subject.name)), sign)?;
    }
    let csv_path = args.out.join("convergence.csv");
    outputs.claim(&csv_path, &[CSV_HEADER.as_bytes()])?;
    let workers =
        Workers::new(args.threads).with_context(|| format!("could not start {} render threads", args.threads))?;
    let references =
        (subjects.iter()).map(|subject| reference_for(args, subject, &workers)).collect::<Result<Vec<_>>>()?;
    std::fs::create_dir_all(&args.out).with_context(|| args.out.display().to_string())?;
    let mut csv = String::from(CSV_HEADER);
    for (subject, (reference, made)) in subjects.iter().zip(references) {
        let name = &subject.name;
        let (width, height) = (reference.image.width, reference.image.height);
        println!("\n{name} at {width}×{height} for {} s per algorithm (reference: {made})", args.budget);
        println!(
            "paths of up to {} segments, camera to light (Whitted: {})",
            Algorithm::Path.default_max_depth(),
            Algorithm::Whitted.default_max_depth()
        );
        let mut runs = Vec::new();
        for &algorithm in &args.algos {
            let mut settings = RenderSettings {
                width,
                height,
                time_limit: Some(args.budget),
                samples_per_pixel: None,
                seed: args.seed,
                ..RenderSettings::for_algorithm(algorithm)
            };
            if let (Method::Vcm(m), Some(merges)) = (&mut settings.method, args.merges) {
                merges.apply(m);
            }
            for line in unseen_lights(&subject.scene, algorithm) {
                eprintln!("warning: {name}: {line}");
            }
            let bar = ProgressBar::new((args.budget * 10.0).ceil() as u64).with_message(format!("{name} {algorithm}"));
            bar.set_style(
                ProgressStyle::with_template("{msg:24} [{bar:40}] {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            let run = measure(&workers, &subject.scene, settings, &reference, Some(&bar))?;
            bar.finish_and_clear();
            for p in &run.log.points {
                let flip = p.flip.map_or(String::new(), |f| format!("{f:.5}"));
                // Seconds to the last bit: which passes were measured for
                // FLIP follows from them, rounded it could not be told
                writeln!(
                    csv,
                    "{name},{algorithm},{},{},{},{:.6e},{:.2e},{flip}",
                    p.seconds, p.samples_per_pixel, p.rays, p.error.rel_mse, p.error.standard_error
                )?;
            }
            run.image.save(&args.out.join(format!("{name}-{algorithm}.png")), 0.0)?;
            runs.push(run);
        }
        println!("{}", table(&runs, args.budget));
        if let Some(reach) = against_path(&runs, args.budget) {
            println!("{reach}");
        }
        let series: Vec<(String, ConvergenceLog)> =
            runs.iter().map(|r| (r.algorithm.label().to_owned(), r.log.clone())).collect();
        let plot_path = args.out.join(format!("{name}.png"));
        let floor = runs.first().and_then(|r| r.log.points.last()).and_then(|p| p.error.noise_floor);
        plot_error_against_time(&format!("{name}: relMSE against time"), &series, floor, &plot_path)
            .map_err(anyhow::Error::msg)?;
        println!("plot → {}", plot_path.display());
    }
    fileio::write_bytes(&csv_path, csv.as_bytes())?;
    println!("\nCSV → {}", csv_path.display());
    Ok(())
}

/// When each algorithm has path tracing's error at the budget for good
/// (`time_to_stay_within`), and how much sooner than path tracing; None
/// without path tracing and another algorithm among `runs`.
pub fn against_path(runs: &[Run], budget: f64) -> Option<String> {
    let path = runs.iter().find(|run| run.algorithm == Algorithm::Path)?;
    if runs.len() < 2 {
        return None;
    }
    let target = path.log.error_at(budget).or(path.log.points.last().map(|p| p.error.rel_mse))?;
    let mut out = format!("path tracing's relMSE at the budget, {}, held from:\n", format_error(Some(target)));
    for run in runs.iter().filter(|run| run.algorithm != Algorithm::Path) {
        let time = run.log.time_to_stay_within(target);
        let sooner = time.filter(|&t| t > 0.0).map_or("—".into(), |t| format!("{:.2}×", budget / t));
        let _ = writeln!(out, "{:<28} {:>10} {:>8}", run.algorithm.label(), format_time(time), sooner);
    }
    Some(out)
}

pub fn table(runs: &[Run], budget: f64) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<28} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>7} {:>8}",
        "algorithm",
        "M samp/s",
        "M rays/s",
        "relMSE 1s",
        "relMSE 4s",
        "at budget",
        "t(1e-2)",
        "t(1e-3)",
        "slope",
        "FLIP"
    );
    for run in runs {
        let log = &run.log;
        let last = log.points.last();
        let _ = writeln!(
            out,
            "{:<28} {:>10.2} {:>10.2} {:>10} {:>10} {:>10} {:>10} {:>10} {:>7} {:>8}",
            run.algorithm.label(),
            run.stats.samples_per_second() / 1e6,
            run.stats.rays_per_second() / 1e6,
            format_error(log.error_at(1.0)),
            format_error(log.error_at(4.0)),
            format_error(log.error_at(budget).or(last.map(|p| p.error.rel_mse))),
            format_time(log.time_to_reach(1e-2)),
            format_time(log.time_to_reach(1e-3)),
            log.loglog_slope().map_or("—".into(), |s| format!("{s:.2}")),
            last.and_then(|p| p.flip).map_or("—".into(), |f| format!("{f:.4}")),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::metrics::ErrorEstimate;

    fn run(algorithm: Algorithm, errors: &[f64]) -> Run {
        let points = errors
            .iter()
            .enumerate()
            .map(|(i, &rel_mse)| ConvergencePoint {
                seconds: (i + 1) as f64,
                samples_per_pixel: i as u32 + 1,
                rays: 0,
                error: ErrorEstimate { rel_mse, standard_error: 0.0, noise_floor: None },
                flip: None,
            })
            .collect();
        Run {
            algorithm,
            log: ConvergenceLog { points },
            stats: PassStats::default(),
            image: LinearImage { width: 0, height: 0, pixels: Vec::new() },
        }
    }

    /// Path tracing ends its 4 s at 0.1; BDPT holds 0.1 from 3 s (1.33×
    /// sooner) though it dipped there at 1 s; VCM never gets there.
    #[test]
    fn each_algorithm_is_timed_to_path_tracings_last_error() {
        let runs = [
            run(Algorithm::Bdpt, &[0.09, 0.2, 0.1, 0.05]),
            run(Algorithm::Path, &[0.4, 0.3, 0.2, 0.1]),
            run(Algorithm::Vcm, &[0.5, 0.4, 0.3, 0.2]),
        ];
        let text = against_path(&runs, 4.0).expect("path tracing is among the runs");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert!(lines[0].contains("1.00e-1"), "{text}");
        let bdpt: Vec<&str> = lines[1].split_whitespace().collect();
        assert_eq!(bdpt[bdpt.len() - 3..], ["3.00", "s", "1.33×"], "{text}");
        let vcm: Vec<&str> = lines[2].split_whitespace().collect();
        assert!(lines[2].starts_with(Algorithm::Vcm.label()) && vcm.ends_with(&["—", "—"]), "{text}");
        assert!(against_path(&runs[2..], 4.0).is_none(), "no path tracing");
        assert!(against_path(&runs[1..2], 4.0).is_none(), "path tracing alone");
    }
}
