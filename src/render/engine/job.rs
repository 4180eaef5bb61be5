//! One job from start to end: the scene compiled, the integrator prepared,
//! a preview, then passes until the job's budget, each pass's statistics
//! and tiles sent as events. A job stops within a tile of being abandoned:
//! every tile checks the generation it belongs to.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use crossbeam_channel::Sender;
use rayon::prelude::*;

use super::events::{Notify, PassStats, RenderEvent, TileUpdate};
use super::workers::{Share, Workers};
use crate::faults::{self, Fault};
use crate::render::film::Film;
use crate::render::integrators::bidir::strategies::StrategyImages;
use crate::render::integrators::photon_map::PhotonMaps;
use crate::render::integrators::{Integrator, PassObserver, Stage};
use crate::render::settings::RenderSettings;
use crate::render::world::camera::{CameraModel, TileRect};
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::World;
use crate::scene::ValidScene;

/// A scene snapshot and how to render it.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub scene: Arc<ValidScene>,
    pub settings: RenderSettings,
    /// Photon maps made earlier for this scene and these settings (loaded
    /// from a file); traced afresh when absent.
    pub photon_maps: Option<Arc<PhotonMaps>>,
    /// Send every tile's image after each pass (what a viewport or a
    /// convergence log reads); a batch render wants only the final image.
    pub stream_tiles: bool,
    /// With each streamed tile, its pixels' estimated variance (a reference
    /// being made while it is used).
    pub stream_variance: bool,
    /// Estimate the render's own relMSE (`PassStats::noise`, unbiased
    /// methods only) now and then: what a viewer without a reference shows.
    pub estimate_noise: bool,
    /// Made as a reference: its variance is kept (odd and even passes
    /// apart) whatever the method, as the errors measured against it take
    /// its noise off. A consistent method's neighbouring passes (VCM's
    /// radius shrinks slowly) are as good as independent for that.
    pub reference: bool,
    /// Send what each strategy of a bidirectional method brings, now and
    /// then, while this is on (the studio's strategy view, which opens and
    /// closes while the job goes on).
    pub strategies: Switch,
    /// Its share of workers it shares with other jobs (1 unless changed).
    pub weight: Weight,
}

/// How many callers' worth of the shared workers a job takes, which its
/// driver may change while it runs (`Share::weight`).
#[derive(Clone, Debug, Default)]
pub struct Weight(Arc<AtomicU32>);

impl Weight {
    pub fn set(&self, weight: u32) {
        self.0.store(weight, Ordering::Relaxed);
    }

    pub fn get(&self) -> u32 {
        self.0.load(Ordering::Relaxed).max(1)
    }
}

/// A flag the driver turns on and off while a job runs.
#[derive(Clone, Debug, Default)]
pub struct Switch(Arc<AtomicBool>);

impl Switch {
    pub fn new(on: bool) -> Self {
        Self(Arc::new(AtomicBool::new(on)))
    }

    pub fn set(&self, on: bool) {
        self.0.store(on, Ordering::Relaxed);
    }

    pub fn is_on(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl RenderJob {
    pub fn new(scene: Arc<ValidScene>, settings: RenderSettings) -> Self {
        Self {
            scene,
            settings,
            photon_maps: None,
            stream_tiles: true,
            stream_variance: false,
            estimate_noise: false,
            reference: false,
            strategies: Switch::default(),
            weight: Weight::default(),
        }
    }
}

/// The job's side of the session: which generation it is, and where its
/// events go.
pub(super) struct JobContext<'a> {
    pub generation: u64,
    pub stream_tiles: bool,
    pub stream_variance: bool,
    pub estimate_noise: bool,
    pub strategies: Switch,
    pub current: &'a AtomicU64,
    pub events: &'a Sender<RenderEvent>,
    pub notify: Option<&'a Notify>,
}

impl JobContext<'_> {
    pub(super) fn send(&self, event: RenderEvent) {
        // The receiver is gone only when the session was dropped, and then
        // nobody is left to tell
        let news = event.is_news();
        let _ = self.events.send(event);
        if let Some(notify) = self.notify {
            notify(news);
        }
    }
}

impl PassObserver for JobContext<'_> {
    fn is_current(&self) -> bool {
        self.current.load(Ordering::Relaxed) == self.generation
    }

    fn wants_tiles(&self) -> bool {
        self.stream_tiles
    }

    fn wants_variance(&self) -> bool {
        self.stream_variance
    }

    fn wants_noise(&self, pass: u32) -> bool {
        // Every pass at first, then every eighth: the estimate moves slowly,
        // and on a fast pass it costs a sixth of the pass
        self.estimate_noise && (pass < 8 || (pass + 1) % 8 == 0)
    }

    fn tile(&self, rect: TileRect, pixels: Vec<[f32; 3]>, variance: Option<Vec<[f32; 3]>>) {
        let generation = self.generation;
        self.send(RenderEvent::Tile(TileUpdate { generation, rect, pixels, preview: false, variance }));
    }

    fn wants_strategies(&self) -> bool {
        self.strategies.is_on()
    }

    fn strategies(&self, images: StrategyImages) {
        self.send(RenderEvent::Strategies { generation: self.generation, images: Arc::new(images) });
    }
}

/// Render `job` on `workers`. Each stage (preparing, the preview, every
/// pass) takes its turn on the shared pool on its own, so a stage is all
/// another job ever waits for (a whole render handed over at once could
/// hold a pane behind a 4096-pass reference), and the job's time is the
/// sum of its stages' times: its own work, not its waiting.
pub(super) fn run_job(workers: &Workers, context: &JobContext, job: &RenderJob) {
    let settings = &job.settings;
    let generation = context.generation;
    if let Some(problem) = settings.problems().into_iter().next() {
        context.send(RenderEvent::Failed { generation, message: problem.to_string() });
        return;
    }
    let camera = CameraModel::new(&job.scene.camera, settings.width, settings.height);
    let (world, visible_radius) = World::for_view(&job.scene, &camera, settings.width, settings.height);
    // The job's own time: its stages' times on the pool, not the time they
    // waited for other sessions' stages
    let mut busy = Duration::ZERO;
    let mut share = Share::default();
    share.weight = job.weight.get();
    let halves = settings.algorithm().is_unbiased() || job.reference;
    // The film is made in the job's time: its sums are written as it is
    // made (`Film::new`), which the first pass did before
    // The world for eight rays at a time, compiled once for every pass
    let ((mut film, lanes), took) = workers.run_in_turn(&mut share, || {
        assert!(!faults::active(Fault::RenderPanics), "an injected bug");
        (Film::new(settings.width, settings.height, settings.tile_size, halves), LaneWorld::new(&world))
    });
    busy += took;
    let stage = Stage { world: &world, camera: &camera, settings, lanes: lanes.as_ref() };
    let (prepared, took) = workers.run_in_turn(&mut share, || {
        Integrator::prepare(&stage, &film, visible_radius, job.photon_maps.clone(), context)
    });
    busy += took;
    let Some(mut integrator) = prepared else {
        return;
    };
    if let Some(stats) = integrator.photon_maps() {
        context.send(RenderEvent::PhotonMaps { generation, stats });
    }
    context.send(RenderEvent::Started { generation, width: settings.width, height: settings.height });

    if settings.preview {
        busy += workers
            .run_in_turn(&mut share, || {
                film.tiles.par_iter().with_max_len(1).for_each(|tile| {
                    if context.is_current() {
                        let pixels = integrator.preview_tile(&stage, tile.rect);
                        let update = TileUpdate { generation, rect: tile.rect, pixels, preview: true, variance: None };
                        context.send(RenderEvent::Tile(update));
                    }
                })
            })
            .1;
    }

    let mut stats = PassStats::default();
    loop {
        let done_spp = settings.samples_per_pixel.is_some_and(|spp| stats.passes >= spp);
        let done_time = settings.time_limit.is_some_and(|limit| stats.passes > 0 && busy.as_secs_f64() >= limit);
        if done_spp || done_time {
            break;
        }
        let pass = settings.first_pass + stats.passes;
        share.weight = job.weight.get();
        let (report, pass_time) = workers.run_in_turn(&mut share, || integrator.pass(&stage, &mut film, pass, context));
        let Some(report) = report else {
            return;
        };
        busy += pass_time;
        stats.rays += report.counters.rays;
        stats.non_finite += report.counters.non_finite;
        stats.passes += 1;
        stats.samples += settings.width as u64 * settings.height as u64;
        stats.pass_time = pass_time;
        stats.elapsed = busy;
        stats.photon = report.photon;
        stats.paths = report.paths;
        stats.noise = report.noise.estimate().or(stats.noise);
        context.send(RenderEvent::PassFinished { generation, stats });
    }
    let image = film.image(|tile| integrator.tile_pixels(&film, tile));
    let variance = film.variance().map(Arc::new);
    let odd = film.odd_image().map(Arc::new);
    context.send(RenderEvent::Finished { generation, image: Arc::new(image), variance, odd, stats });
}
