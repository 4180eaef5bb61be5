//! The progressive engine: passes over tiles in parallel, each finished tile
//! sent at once, stopped by a generation counter that every tile checks, so a
//! restart never waits for a pass to end. The studio and the CLI both drive it
//! through a `RenderSession`.

pub mod tiles;

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender};
use rayon::prelude::*;

use crate::render::engine::tiles::{tile_layout, TileAccumulator, TileRect};
use crate::render::image::LinearImage;
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::path_lanes::{CameraTile, PathLanes};
use crate::render::integrators::photon::{PhotonRenderer, PhotonScratch};
use crate::render::integrators::photon_map::trace::{trace_photons, MapKind};
use crate::render::integrators::photon_map::{PhotonKdTree, PhotonMapStats, PhotonMaps, QueryStats};
use crate::render::integrators::sppm::camera_pass;
use crate::render::integrators::{path, whitted, Counters};
use crate::render::settings::{Algorithm, RenderSettings};
use crate::render::world::camera::CameraModel;
use crate::render::world::rng::PassStreams;
use crate::render::world::World;
use crate::scene::{Rgb, Scene};

/// A scene snapshot and how to render it.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub scene: Arc<Scene>,
    pub settings: RenderSettings,
    /// Photon maps made earlier for this scene and these settings (loaded
    /// from a file); traced afresh when absent.
    pub photon_maps: Option<Arc<PhotonMaps>>,
    /// Send every tile's image after each pass (what a viewport or a
    /// convergence log reads); a batch render wants only the final image.
    pub stream_tiles: bool,
}

impl RenderJob {
    pub fn new(scene: Arc<Scene>, settings: RenderSettings) -> Self {
        Self { scene, settings, photon_maps: None, stream_tiles: true }
    }
}

/// Totals after a pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassStats {
    /// Passes completed (= samples per pixel for Whitted and path tracing).
    pub passes: u32,
    pub elapsed: Duration,
    pub pass_time: Duration,
    /// Camera samples traced so far.
    pub samples: u64,
    pub rays: u64,
    /// Samples that came out NaN or infinite and were dropped.
    pub non_finite: u64,
    /// Photon work of the last pass (photon mapping and SPPM).
    pub photon: PhotonPassStats,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonPassStats {
    /// k-NN queries made while rendering the pass.
    pub queries: QueryStats,
    /// SPPM: photons traced and stored this pass, and the time it took.
    pub photons_traced: u64,
    pub photons_stored: u64,
    pub trace_time: Duration,
    /// SPPM: mean gather radius over pixels after the pass.
    pub mean_radius: f32,
}

impl PassStats {
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

#[derive(Clone, Debug)]
pub struct TileUpdate {
    pub generation: u64,
    pub rect: TileRect,
    /// Mean linear radiance, row-major within the tile.
    pub pixels: Vec<[f32; 3]>,
    /// A coarse block-filled preview, not yet part of the estimate.
    pub preview: bool,
}

/// What the engine tells its driver. Every event names the generation (the
/// job) it belongs to, so stale ones can be dropped.
#[derive(Clone, Debug)]
pub enum RenderEvent {
    Started {
        generation: u64,
        width: u32,
        height: u32,
    },
    Tile(TileUpdate),
    /// Photon mapping traced (or loaded) its maps.
    PhotonMaps {
        generation: u64,
        stats: PhotonMapStats,
    },
    PassFinished {
        generation: u64,
        stats: PassStats,
    },
    Finished {
        generation: u64,
        image: Arc<LinearImage>,
        stats: PassStats,
    },
    Failed {
        generation: u64,
        message: String,
    },
}

impl RenderEvent {
    pub fn generation(&self) -> u64 {
        match self {
            RenderEvent::Started { generation, .. }
            | RenderEvent::PassFinished { generation, .. }
            | RenderEvent::PhotonMaps { generation, .. }
            | RenderEvent::Finished { generation, .. }
            | RenderEvent::Failed { generation, .. } => *generation,
            RenderEvent::Tile(tile) => tile.generation,
        }
    }
}

enum Command {
    Start(u64, RenderJob),
    Shutdown,
}

/// Called after events are sent (the studio passes `ctx.request_repaint`).
pub type Notify = Arc<dyn Fn() + Send + Sync>;

/// Handle to a background render worker: start (or restart) with a new scene
/// snapshot, cancel, and read events. Never blocks the caller.
pub struct RenderSession {
    commands: Sender<Command>,
    events: Receiver<RenderEvent>,
    generation: Arc<AtomicU64>,
    worker: Option<JoinHandle<()>>,
}

impl RenderSession {
    /// Start the session's worker thread (the OS may refuse one).
    pub fn new(notify: Option<Notify>) -> std::io::Result<Self> {
        let (commands, command_rx) = crossbeam_channel::unbounded();
        let (event_tx, events) = crossbeam_channel::unbounded();
        let generation = Arc::new(AtomicU64::new(0));
        let worker_generation = generation.clone();
        let worker = std::thread::Builder::new()
            .name("render-worker".into())
            .spawn(move || worker_loop(command_rx, event_tx, worker_generation, notify))?;
        Ok(Self { commands, events, generation, worker: Some(worker) })
    }

    /// Start rendering `job`, abandoning whatever was in flight. Returns the
    /// new generation; events of older ones may still arrive and should be dropped.
    pub fn start(&self, job: RenderJob) -> u64 {
        let generation = self.generation.fetch_add(1, Ordering::SeqCst) + 1;
        let _ = self.commands.send(Command::Start(generation, job));
        generation
    }

    /// Stop the current job; the worker goes idle.
    pub fn cancel(&self) {
        self.generation.fetch_add(1, Ordering::SeqCst);
    }

    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    pub fn events(&self) -> &Receiver<RenderEvent> {
        &self.events
    }
}

impl Drop for RenderSession {
    fn drop(&mut self) {
        self.cancel();
        let _ = self.commands.send(Command::Shutdown);
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

fn worker_loop(
    commands: Receiver<Command>,
    events: Sender<RenderEvent>,
    generation: Arc<AtomicU64>,
    notify: Option<Notify>,
) {
    let mut pools: Option<(usize, rayon::ThreadPool)> = None;
    while let Ok(mut command) = commands.recv() {
        // Only the newest queued job matters
        while let Ok(newer) = commands.try_recv() {
            command = newer;
        }
        let Command::Start(job_generation, job) = command else {
            return;
        };
        if generation.load(Ordering::SeqCst) != job_generation {
            continue;
        }
        let threads = job.settings.threads;
        if pools.as_ref().is_none_or(|(n, _)| *n != threads) {
            match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
                Ok(pool) => pools = Some((threads, pool)),
                Err(e) => {
                    let message = format!("could not start {threads} render threads: {e}");
                    let _ = events.send(RenderEvent::Failed { generation: job_generation, message });
                    continue;
                }
            }
        }
        if let Some((_, pool)) = &pools {
            let context = JobContext {
                generation: job_generation,
                stream_tiles: job.stream_tiles,
                current: &generation,
                events: &events,
                notify: notify.as_ref(),
            };
            pool.install(|| run_job(&context, &job));
        }
    }
}

struct JobContext<'a> {
    generation: u64,
    stream_tiles: bool,
    current: &'a AtomicU64,
    events: &'a Sender<RenderEvent>,
    notify: Option<&'a Notify>,
}

impl JobContext<'_> {
    fn is_current(&self) -> bool {
        self.current.load(Ordering::Relaxed) == self.generation
    }

    /// A tile's image after a pass, if the job streams them.
    fn send_tile(&self, buffer: &TileAccumulator) {
        if self.stream_tiles {
            let pixels = buffer.mean();
            self.send(RenderEvent::Tile(TileUpdate {
                generation: self.generation,
                rect: buffer.rect,
                pixels,
                preview: false,
            }));
        }
    }

    fn send(&self, event: RenderEvent) {
        let _ = self.events.send(event);
        if let Some(notify) = self.notify {
            notify();
        }
    }
}

/// Sample index used for the coarse preview, outside any real pass's range.
const PREVIEW_SAMPLE: u64 = u64::MAX;
const PREVIEW_BLOCK: u32 = 8;

fn run_job(context: &JobContext, job: &RenderJob) {
    let settings = &job.settings;
    let generation = context.generation;
    if let Some(problem) = job.scene.validate().into_iter().next() {
        context.send(RenderEvent::Failed { generation, message: problem.to_string() });
        return;
    }
    if let Some(problem) = settings.problems().into_iter().next() {
        context.send(RenderEvent::Failed { generation, message: problem.to_string() });
        return;
    }
    let camera = CameraModel::new(&job.scene.camera, settings.width, settings.height);
    let (world, visible_radius) = World::for_view(&job.scene, &camera, settings.width, settings.height);
    let start = Instant::now();
    let method = match settings.algorithm {
        Algorithm::Whitted => Method::Sample,
        Algorithm::Path => PathLanes::new(&world).map_or(Method::Sample, Method::PathLanes),
        Algorithm::Photon => {
            let maps = match &job.photon_maps {
                Some(maps) => maps.clone(),
                None => Arc::new(PhotonMaps::build(
                    &world,
                    &settings.photon,
                    settings.seed,
                    settings.max_depth,
                    visible_radius,
                )),
            };
            if !context.is_current() {
                return;
            }
            context.send(RenderEvent::PhotonMaps { generation, stats: maps.stats });
            Method::Photon(maps)
        }
        Algorithm::Sppm => Method::Sppm,
    };
    let frame = FrameContext {
        camera,
        sppm_initial_radius: if settings.photon.sppm_initial_radius > 0.0 {
            settings.photon.sppm_initial_radius
        } else {
            (visible_radius * 0.02).max(1e-6)
        },
        world,
        method,
        settings,
    };
    context.send(RenderEvent::Started { generation, width: settings.width, height: settings.height });
    let tiles = tile_layout(settings.width, settings.height, settings.tile_size);

    if settings.preview {
        tiles.par_iter().for_each(|rect| {
            if context.is_current() {
                let pixels = frame.preview_tile(*rect);
                context.send(RenderEvent::Tile(TileUpdate { generation, rect: *rect, pixels, preview: true }));
            }
        });
    }

    let sppm = matches!(frame.method, Method::Sppm);
    let mut buffers: Vec<TileAccumulator> = tiles.iter().map(|r| TileAccumulator::new(*r, sppm)).collect();
    let mut stats = PassStats::default();
    loop {
        let done_spp = settings.samples_per_pixel.is_some_and(|spp| stats.passes >= spp);
        let done_time =
            settings.time_limit.is_some_and(|limit| stats.passes > 0 && start.elapsed().as_secs_f64() >= limit);
        if done_spp || done_time {
            break;
        }
        let pass_start = Instant::now();
        let pass = stats.passes;
        let mut photon = PhotonPassStats::default();
        let per_tile: Vec<Counters> = if sppm {
            match frame.sppm_pass(context, &mut buffers, pass, &mut photon) {
                Some(counters) => counters,
                None => return,
            }
        } else {
            buffers
                .par_iter_mut()
                .map(|buffer| {
                    let mut counters = Counters::default();
                    if context.is_current() {
                        frame.render_tile_pass(buffer, pass, &mut counters);
                        context.send_tile(buffer);
                    }
                    counters
                })
                .collect()
        };
        if !context.is_current() {
            return;
        }
        for counters in &per_tile {
            stats.rays += counters.rays;
            stats.non_finite += counters.non_finite;
            photon.queries.add(&counters.queries);
        }
        stats.passes += 1;
        stats.samples += settings.width as u64 * settings.height as u64;
        stats.pass_time = pass_start.elapsed();
        stats.elapsed = start.elapsed();
        stats.photon = photon;
        context.send(RenderEvent::PassFinished { generation, stats });
    }
    let image = assemble(settings.width, settings.height, &buffers);
    context.send(RenderEvent::Finished { generation, image: Arc::new(image), stats });
}

fn assemble(width: u32, height: u32, buffers: &[TileAccumulator]) -> LinearImage {
    let mut image = LinearImage::new(width, height);
    for buffer in buffers {
        let rect = buffer.rect;
        for (i, pixel) in buffer.mean().into_iter().enumerate() {
            let (x, y) = (rect.x + i as u32 % rect.width, rect.y + i as u32 / rect.width);
            image.pixels[(y * width + x) as usize] = pixel;
        }
    }
    image
}

/// How a pass turns into pixels.
enum Method {
    /// Whitted and path tracing: independent samples per pixel, averaged.
    Sample,
    /// Path tracing of a scene of spheres, eight paths at a time: the same
    /// samples as `Sample`, bit for bit.
    PathLanes(PathLanes),
    /// Photon mapping: samples per pixel against fixed maps.
    Photon(Arc<PhotonMaps>),
    /// SPPM: visible points, a photon pass, and a per-pixel update.
    Sppm,
}

/// Everything a pass reads: shared, immutable, built once per job.
struct FrameContext<'a> {
    world: World,
    camera: CameraModel,
    method: Method,
    sppm_initial_radius: f32,
    settings: &'a RenderSettings,
}

impl FrameContext<'_> {
    /// The streams of sample `sample` of every pixel.
    fn streams(&self, sample: u64) -> PassStreams {
        PassStreams::new(sample, self.settings.seed)
    }

    /// One finite, non-negative sample (clamped only if asked), or None.
    fn sample(
        &self,
        x: u32,
        y: u32,
        streams: PassStreams,
        counters: &mut Counters,
        scratch: &mut Option<PhotonScratch>,
    ) -> Option<Rgb> {
        let settings = self.settings;
        let (ray, mut sampler) = self.camera.sample_ray(x, y, streams);
        let value = match (&self.method, scratch) {
            (Method::Photon(maps), Some(scratch)) => {
                let renderer = PhotonRenderer {
                    world: &self.world,
                    scope: PathScope::new(&self.world, ray.origin),
                    maps,
                    settings: &settings.photon,
                    max_depth: settings.max_depth,
                };
                renderer.radiance(&ray, &mut sampler, counters, scratch)
            }
            _ if settings.algorithm == Algorithm::Whitted => {
                whitted::radiance(&self.world, &ray, settings.max_depth.max(1), &mut sampler, counters)
            }
            _ => path::radiance(&self.world, &ray, settings.max_depth, &mut sampler, counters),
        };
        self.finite(value, counters)
    }

    fn finite(&self, value: Rgb, counters: &mut Counters) -> Option<Rgb> {
        if !value.is_finite() {
            counters.non_finite += 1;
            return None;
        }
        let value = value.max(Rgb::ZERO);
        let clamp = self.settings.firefly_clamp;
        Some(if clamp > 0.0 { value.min(Rgb::splat(clamp)) } else { value })
    }

    fn scratch(&self) -> Option<PhotonScratch> {
        matches!(self.method, Method::Photon(_))
            .then(|| PhotonScratch::new(self.settings.photon.k_nearest.max(8) as usize))
    }

    fn render_tile_pass(&self, buffer: &mut TileAccumulator, pass: u32, counters: &mut Counters) {
        let rect = buffer.rect;
        // Row by row, as the buffer's sums are laid out
        let pixels =
            (0..rect.height).flat_map(|row| (0..rect.width).map(move |column| (rect.x + column, rect.y + row)));
        let add = |sum: &mut [f64; 3], value: Option<Rgb>| {
            let value = value.unwrap_or(Rgb::ZERO);
            for c in 0..3 {
                sum[c] += value[c] as f64;
            }
        };
        let streams = self.streams(pass as u64);
        if let Method::PathLanes(lanes) = &self.method {
            let mut values = vec![Rgb::ZERO; buffer.sums.len()];
            let tile = CameraTile { camera: &self.camera, rect, streams };
            lanes.radiance(&self.world, &tile, self.settings.max_depth, &mut values, counters);
            for (sum, value) in buffer.sums.iter_mut().zip(values) {
                add(sum, self.finite(value, counters));
            }
        } else {
            let mut scratch = self.scratch();
            for (sum, (x, y)) in buffer.sums.iter_mut().zip(pixels) {
                add(sum, self.sample(x, y, streams, counters, &mut scratch));
            }
            if let Some(scratch) = scratch {
                counters.queries.add(&scratch.queries);
            }
        }
        buffer.samples += 1;
    }

    /// One SPPM pass: visible points for every pixel, this pass's photons,
    /// then each pixel's update. None if the job was abandoned.
    fn sppm_pass(
        &self,
        context: &JobContext,
        buffers: &mut [TileAccumulator],
        pass: u32,
        stats: &mut PhotonPassStats,
    ) -> Option<Vec<Counters>> {
        let settings = self.settings;
        let mut per_tile: Vec<Counters> = buffers
            .par_iter_mut()
            .map(|buffer| {
                let mut counters = Counters::default();
                if !context.is_current() {
                    return counters;
                }
                let (rect, streams) = (buffer.rect, self.streams(pass as u64));
                for (i, pixel) in buffer.sppm.iter_mut().enumerate() {
                    let (x, y) = (rect.x + i as u32 % rect.width, rect.y + i as u32 / rect.width);
                    let (ray, mut sampler) = self.camera.sample_ray(x, y, streams);
                    let (direct, visible) =
                        camera_pass(&self.world, &ray, settings.max_depth, &mut sampler, &mut counters);
                    pixel.direct += self.finite(direct, &mut counters).unwrap_or(Rgb::ZERO);
                    pixel.visible = visible;
                    if pixel.radius == 0.0 {
                        pixel.radius = self.sppm_initial_radius;
                    }
                }
                counters
            })
            .collect();
        if !context.is_current() {
            return None;
        }
        let trace_start = Instant::now();
        let count = settings.photon.sppm_photons_per_pass as u64;
        let photons =
            trace_photons(&self.world, MapKind::Indirect, count, pass as u64, settings.seed, settings.max_depth);
        stats.photons_traced = count;
        stats.photons_stored = photons.len() as u64;
        let tree = PhotonKdTree::build(photons);
        stats.trace_time = trace_start.elapsed();
        if !context.is_current() {
            return None;
        }
        let alpha = settings.photon.sppm_alpha;
        let radii: Vec<(f64, usize)> = buffers
            .par_iter_mut()
            .map(|buffer| {
                if !context.is_current() {
                    return (0.0, 0);
                }
                let mut sum = 0.0;
                for pixel in buffer.sppm.iter_mut() {
                    pixel.gather(&tree, alpha);
                    sum += pixel.radius as f64;
                }
                buffer.samples += 1;
                context.send_tile(buffer);
                (sum, buffer.sppm.len())
            })
            .collect();
        let (sum, count) = radii.iter().fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        stats.mean_radius = (sum / count.max(1) as f64) as f32;
        per_tile.push(Counters::default());
        Some(per_tile)
    }

    /// One sample per block, copied over the block.
    fn preview_tile(&self, rect: TileRect) -> Vec<[f32; 3]> {
        let mut pixels = vec![[0.0; 3]; (rect.width * rect.height) as usize];
        let mut counters = Counters::default();
        let mut scratch = self.scratch();
        for by in (0..rect.height).step_by(PREVIEW_BLOCK as usize) {
            for bx in (0..rect.width).step_by(PREVIEW_BLOCK as usize) {
                let (w, h) = (PREVIEW_BLOCK.min(rect.width - bx), PREVIEW_BLOCK.min(rect.height - by));
                let (x, y) = (rect.x + bx + w / 2, rect.y + by + h / 2);
                let value = match self.method {
                    // SPPM has no estimate before its first pass: show direct light
                    Method::Sppm => {
                        let (ray, mut sampler) = self.camera.sample_ray(x, y, self.streams(PREVIEW_SAMPLE));
                        let direct =
                            camera_pass(&self.world, &ray, self.settings.max_depth, &mut sampler, &mut counters).0;
                        self.finite(direct, &mut counters)
                    }
                    _ => self.sample(x, y, self.streams(PREVIEW_SAMPLE), &mut counters, &mut scratch),
                }
                .unwrap_or(Rgb::ZERO);
                for y in by..by + h {
                    for x in bx..bx + w {
                        pixels[(y * rect.width + x) as usize] = value.to_array();
                    }
                }
            }
        }
        pixels
    }
}

/// Render a job to completion on its own session, for tests and tools that
/// want just the image (and the final statistics).
pub fn render_blocking(job: &RenderJob) -> Result<(LinearImage, PassStats), String> {
    let session = RenderSession::new(None).map_err(|e| format!("could not start the render worker: {e}"))?;
    let generation = session.start(RenderJob { stream_tiles: false, ..job.clone() });
    for event in session.events().iter() {
        match event {
            RenderEvent::Finished { generation: g, image, stats } if g == generation => {
                return Ok((Arc::try_unwrap(image).unwrap_or_else(|shared| (*shared).clone()), stats));
            }
            RenderEvent::Failed { generation: g, message } if g == generation => return Err(message),
            _ => {}
        }
    }
    Err("the render worker stopped".into())
}
