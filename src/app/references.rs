//! The scene's reference, wherever it comes from: built in (a preset as
//! shipped), the cache (an edit undone, a file reopened), rendered in the
//! background while the panes run (on its own share of the threads), or a
//! pane's image promoted to it. The panes' errors are measured against
//! whatever it holds now; it says which method made it and how converged it
//! is. Files are read and written on a thread of its own: the UI never
//! waits on a disk.

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender};
use eframe::egui;

use crate::analysis::metrics::rel_mse_against;
use crate::analysis::reference::{
    embedded, reference_key, reference_method, reference_settings, reference_size, Reference, ReferenceCache,
    ReferenceInfo, ReferenceMethod, REFERENCE_PASSES,
};
use crate::render::film::NoiseEstimate;
use crate::render::{Algorithm, LinearImage, RenderEvent, RenderJob, RenderSession, Weight, Workers};
use crate::scene::ValidScene;

/// A reference abandoned after this many passes is kept in the cache: an
/// edit undone finds it, rough as it is.
const KEPT_PASSES: u32 = 16;

/// A background reference is young while its own relMSE is above this:
/// it then takes turns on the threads as all the panes together twice
/// over, since a reference noisier than a few times a pane's error cannot
/// measure it (`pane::NOISE_OVER_ERROR`), and the presets' fastest panes
/// reach about this much in their first half minute.
const YOUNG_NOISE: f64 = 2e-3;

/// Where the current reference comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// Being looked for on the reference thread.
    Looking,
    BuiltIn,
    Cache,
    /// Rendering in the background (or stopped, or done).
    Rendering(Progress),
    /// Pane `pane`'s image, made by `algorithm`.
    Promoted {
        pane: usize,
        algorithm: Algorithm,
    },
    /// No reference can be made here (the OS refused the threads).
    Unavailable(String),
}

/// How far the background reference has come.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    pub method: ReferenceMethod,
    pub passes: u32,
    pub target: u32,
    pub seconds: f64,
    /// Its own estimated relMSE (unbiased methods).
    pub noise: Option<NoiseEstimate>,
    pub running: bool,
}

/// The reference of one scene revision.
struct Current {
    key: String,
    scene: Arc<ValidScene>,
    size: (u32, u32),
    method: ReferenceMethod,
    reference: Option<Reference>,
    source: Source,
    /// When the document reached this revision, and how long after it the
    /// background reference's first own error estimate came (what a user
    /// waits for to see an error on an edited scene).
    followed_at: Instant,
    first_estimate_after: Option<Duration>,
    /// A found reference's own relMSE (from its variance), worked out once.
    found_noise: Option<f64>,
}

enum Request {
    Find { key: String, scene: Arc<ValidScene>, size: (u32, u32) },
    Keep(Box<Reference>),
    Stop,
}

enum Reply {
    Found { key: String, reference: Option<Box<Reference>>, built_in: bool },
    Kept(Result<String, String>),
}

/// The reference thread: looks references up (built in, then the cache)
/// and keeps them in the cache, in the order asked.
fn store_loop(
    cache: Option<ReferenceCache>,
    requests: Receiver<Request>,
    replies: Sender<Reply>,
    notify: egui::Context,
) {
    while let Ok(first) = requests.recv() {
        let pending: Vec<Request> = std::iter::once(first).chain(requests.try_iter()).collect();
        // Of several lookups queued (a slider dragged), only the newest matters
        let newest = pending.iter().rposition(|r| matches!(r, Request::Find { .. }));
        for (i, request) in pending.into_iter().enumerate() {
            match request {
                Request::Stop => return,
                Request::Find { .. } if Some(i) != newest => {}
                request => answer(&cache, request, &replies),
            }
        }
        notify.request_repaint();
    }
}

fn answer(cache: &Option<ReferenceCache>, request: Request, replies: &Sender<Reply>) {
    let reply = match request {
        Request::Find { key, scene, size } => {
            match embedded(&scene).filter(|r| (r.image.width, r.image.height) == size) {
                Some(reference) => Reply::Found { key, reference: Some(Box::new(reference)), built_in: true },
                None => Reply::Found {
                    reference: cache.as_ref().and_then(|c| c.get(&key)).map(Box::new),
                    key,
                    built_in: false,
                },
            }
        }
        Request::Keep(reference) => Reply::Kept(match cache {
            Some(cache) => cache.put(&reference).map(|p| p.display().to_string()).map_err(|e| e.to_string()),
            None => Err("no cache folder (neither XDG_CACHE_HOME nor HOME is set)".into()),
        }),
        Request::Stop => return,
    };
    // The studio is gone only when it is being dropped
    let _ = replies.send(reply);
}

pub struct References {
    current: Option<Current>,
    /// The background render's session, on the panes' workers.
    session: Option<RenderSession>,
    /// Its share of the workers, and that share while it is young.
    weight: Weight,
    young_weight: u32,
    generation: u64,
    /// The image and variance assembled from the background render's tiles.
    image: LinearImage,
    variance: LinearImage,
    requests: Sender<Request>,
    replies: Receiver<Reply>,
    store: Option<JoinHandle<()>>,
}

impl References {
    /// Rendering on `workers` (the panes' own, in turns with them; None:
    /// the OS refused them), keeping references in `cache`. Errors are said
    /// where the reference shows.
    pub fn new(ctx: &egui::Context, workers: Option<&Workers>, cache: Option<ReferenceCache>) -> Self {
        let (requests, requests_rx) = crossbeam_channel::unbounded();
        let (replies_tx, replies) = crossbeam_channel::unbounded();
        let notify = ctx.clone();
        let store = std::thread::Builder::new()
            .name("references".into())
            .spawn(move || store_loop(cache, requests_rx, replies_tx, notify))
            .ok();
        let repaint = ctx.clone();
        let notify: crate::render::engine::Notify = Arc::new(move |news| super::status::repaint(&repaint, news));
        Self {
            current: None,
            session: workers.and_then(|w| RenderSession::new(w, Some(notify)).ok()),
            weight: Weight::default(),
            young_weight: 1,
            generation: 0,
            image: LinearImage::new(0, 0),
            variance: LinearImage::new(0, 0),
            requests,
            replies,
            store,
        }
    }

    /// The reference the panes are measured against now.
    pub fn reference(&self) -> Option<&Reference> {
        self.current.as_ref().and_then(|c| c.reference.as_ref())
    }

    /// Where it comes from.
    pub fn source(&self) -> Option<&Source> {
        self.current.as_ref().map(|c| &c.source)
    }

    /// How many panes render beside it: while it is young, a background
    /// reference takes turns on the threads as twice all of them together.
    pub fn set_panes(&mut self, panes: usize) {
        self.young_weight = 2 * panes.max(1) as u32;
    }

    /// Follow the document to `scene`, a new valid revision: its reference
    /// is looked for, and rendered if there is none. The one being made for
    /// an earlier revision stops (and is kept, if it has come far enough).
    pub fn follow(&mut self, scene: &Arc<ValidScene>) {
        let method = reference_method(scene);
        let size = reference_size(scene);
        let key = reference_key(scene, size.0, size.1, method.algorithm);
        if self.current.as_ref().is_some_and(|c| c.key == key) {
            return;
        }
        self.keep_abandoned();
        let request = Request::Find { key: key.clone(), scene: scene.clone(), size };
        let source = match self.requests.send(request) {
            Ok(()) => Source::Looking,
            Err(_) => Source::Unavailable("the reference thread could not start".into()),
        };
        let followed_at = Instant::now();
        self.current = Some(Current {
            key,
            scene: scene.clone(),
            size,
            method,
            reference: None,
            source,
            followed_at,
            first_estimate_after: None,
            found_noise: None,
        });
        if self.store.is_none() {
            // Without the thread nothing is found: render at once
            self.render();
        }
    }

    /// Make pane `pane`'s image (by `algorithm`) the reference, in place of
    /// whatever it was; a background render stops. Its size must divide
    /// the pane's (it is compared as the panes are).
    pub fn promote(&mut self, pane: usize, algorithm: Algorithm, image: &LinearImage) -> Result<(), String> {
        let Some(current) = &mut self.current else { return Err("the scene is not valid".into()) };
        let (width, height) = current.size;
        let image = image
            .at_size(width, height)
            .ok_or_else(|| format!("a {}×{} image cannot be compared at {width}×{height}", image.width, image.height))?
            .into_owned();
        if let Some(session) = &self.session {
            session.cancel();
        }
        let info = ReferenceInfo {
            scene: format!("pane {}", pane + 1),
            key: String::new(),
            algorithm: algorithm.name().into(),
            width,
            height,
            samples_per_pixel: 0,
            seconds: 0.0,
            seed: 0,
            program_version: env!("CARGO_PKG_VERSION").into(),
        };
        current.reference = Some(Reference { image, variance: None, info });
        current.source = Source::Promoted { pane, algorithm };
        Ok(())
    }

    /// Stop the background render (what it has stays the reference) or
    /// go on with it from the start.
    pub fn toggle(&mut self) {
        let Some(current) = &mut self.current else { return };
        match &mut current.source {
            Source::Rendering(progress) if progress.running => {
                progress.running = false;
                if let Some(session) = &self.session {
                    session.cancel();
                }
                self.keep_abandoned();
            }
            _ => self.render(),
        }
    }

    /// Take what the reference thread and the background render sent.
    /// Returns a message for the status bar, if any.
    pub fn poll(&mut self) -> Option<String> {
        let mut message = None;
        let mut missing = false;
        while let Ok(reply) = self.replies.try_recv() {
            match reply {
                Reply::Found { key, reference, built_in } => {
                    let Some(current) = self.current.as_mut().filter(|c| c.key == key) else { continue };
                    match reference {
                        Some(reference) => {
                            let own = rel_mse_against(&reference.image, &reference).ok();
                            current.found_noise = own.and_then(|e| e.noise_floor);
                            current.reference = Some(*reference);
                            current.source = if built_in { Source::BuiltIn } else { Source::Cache };
                        }
                        None => missing = true,
                    }
                }
                Reply::Kept(Err(e)) => message = Some(format!("could not keep the reference: {e}")),
                Reply::Kept(Ok(_)) => {}
            }
        }
        if missing {
            self.render();
        }
        if let Some(failure) = self.take_render_events() {
            message = Some(failure);
        }
        message
    }

    /// The background render's events: tiles into the image, passes into
    /// the reference; the finished reference kept. Returns a failure.
    fn take_render_events(&mut self) -> Option<String> {
        let session = self.session.as_ref()?;
        let mut failure = None;
        let mut finished = false;
        while let Ok(event) = session.events().try_recv() {
            let Some(current) = self.current.as_mut().filter(|_| event.generation() == self.generation) else {
                continue;
            };
            let Source::Rendering(progress) = &mut current.source else { continue };
            match event {
                RenderEvent::Tile(tile) => {
                    let width = self.image.width;
                    for (i, pixel) in tile.pixels.iter().enumerate() {
                        let (x, y) = tile.rect.pixel(i);
                        if x < width && y < self.image.height {
                            let at = (y * width + x) as usize;
                            self.image.pixels[at] = *pixel;
                            if let Some(variance) = &tile.variance {
                                self.variance.pixels[at] = variance[i];
                            }
                        }
                    }
                }
                RenderEvent::PassFinished { stats, .. } => {
                    progress.passes = stats.passes;
                    progress.seconds = stats.elapsed.as_secs_f64();
                    progress.noise = stats.noise;
                    if stats.noise.is_some() && current.first_estimate_after.is_none() {
                        current.first_estimate_after = Some(current.followed_at.elapsed());
                    }
                    let young = stats.noise.is_none_or(|n| n.rel_mse > YOUNG_NOISE);
                    self.weight.set(if young { self.young_weight } else { 1 });
                    let reference = assembled(current, &self.image, &self.variance);
                    current.reference = reference;
                }
                RenderEvent::Finished { .. } => {
                    progress.running = false;
                    finished = true;
                }
                RenderEvent::Failed { message, .. } => {
                    failure = Some(format!("the reference could not be rendered: {message}"));
                    current.source = Source::Unavailable(message);
                }
                RenderEvent::Started { .. } | RenderEvent::PhotonMaps { .. } | RenderEvent::Strategies { .. } => {}
            }
        }
        if finished {
            self.keep_current();
        }
        failure
    }

    /// Start rendering the current revision's reference in the background.
    fn render(&mut self) {
        let Some(current) = &mut self.current else { return };
        let Some(session) = &self.session else {
            current.source = Source::Unavailable("the render threads could not start".into());
            return;
        };
        let (width, height) = current.size;
        let settings = reference_settings(current.method.algorithm, width, height);
        let target = settings.samples_per_pixel.unwrap_or(0);
        let mut job = RenderJob::new(current.scene.clone(), settings);
        job.stream_variance = true;
        job.estimate_noise = true;
        job.reference = true;
        self.weight.set(self.young_weight);
        job.weight = self.weight.clone();
        self.generation = session.start(job);
        self.image = LinearImage::new(width, height);
        self.variance = LinearImage::new(width, height);
        let progress = Progress { method: current.method, passes: 0, target, seconds: 0.0, noise: None, running: true };
        current.source = Source::Rendering(progress);
        current.reference = None;
    }

    /// Keep the background reference of the revision being left, if it has
    /// come far enough to be worth finding again.
    fn keep_abandoned(&mut self) {
        let far_enough = self.current.as_ref().is_some_and(|c| {
            matches!(&c.source, Source::Rendering(p) if p.passes >= KEPT_PASSES) && c.reference.is_some()
        });
        if far_enough {
            if let Some(session) = &self.session {
                session.cancel();
            }
            self.keep_current();
        }
    }

    fn keep_current(&mut self) {
        if let Some(reference) = self.current.as_ref().and_then(|c| c.reference.clone()) {
            // The thread is gone only when the studio is being dropped
            let _ = self.requests.send(Request::Keep(Box::new(reference)));
        }
    }

    /// One line: where the reference comes from, how it was made, how far
    /// it has come; stop it, or render it (again).
    pub fn reference_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(self.describe());
            let button = match self.source() {
                Some(Source::Rendering(p)) if p.running => {
                    Some(("Stop", "Stop rendering; what it has stays the reference"))
                }
                Some(Source::Rendering(_) | Source::Cache | Source::Promoted { .. }) => {
                    Some(("Render again", "Render this scene's reference afresh in the background"))
                }
                _ => None,
            };
            if let Some((label, hint)) = button {
                if ui.small_button(label).on_hover_text(hint).clicked() {
                    self.toggle();
                }
            }
        });
    }

    /// How long after the scene's last change the background reference
    /// gave its first own error estimate, if it has (what a headless
    /// screenshot run reports).
    pub fn first_estimate_after(&self) -> Option<Duration> {
        self.current.as_ref().and_then(|c| c.first_estimate_after)
    }

    /// What `reference_ui` says of the reference.
    pub fn describe(&self) -> String {
        let Some(current) = &self.current else { return "Reference: none (the scene is not valid)".into() };
        let made = |r: &Reference| {
            let noise = current.found_noise.map_or(String::new(), |n| format!(", its own relMSE {n:.1e}"));
            format!("{}, {} of {REFERENCE_PASSES} spp{noise}", r.info.algorithm, r.info.samples_per_pixel)
        };
        match (&current.source, &current.reference) {
            (Source::Looking, _) => "Reference: looking…".into(),
            (Source::BuiltIn, Some(r)) => format!("Reference: built in ({})", made(r)),
            (Source::Cache, Some(r)) => format!("Reference: from the cache ({})", made(r)),
            (Source::Promoted { pane, algorithm }, _) => {
                format!("Reference: pane {}'s image ({}; no noise estimate)", pane + 1, algorithm.label())
            }
            (Source::Rendering(p), _) => {
                let state = if p.running { "rendering" } else { "stopped" };
                let noise = p.noise.map_or(String::new(), |n| format!(", its own relMSE {:.1e}", n.rel_mse));
                format!(
                    "Reference: {state} by {} — {}/{} spp, {:.0} s{noise}",
                    p.method.reason, p.passes, p.target, p.seconds
                )
            }
            (Source::Unavailable(why), _) => format!("Reference: none ({why})"),
            (Source::BuiltIn | Source::Cache, None) => "Reference: none".into(),
        }
    }
}

/// The reference as the background render's tiles have it: `image`, and
/// `variance` once it means something (an unbiased method, two passes).
fn assembled(current: &Current, image: &LinearImage, variance: &LinearImage) -> Option<Reference> {
    let Source::Rendering(progress) = &current.source else { return None };
    let algorithm = progress.method.algorithm;
    let info = ReferenceInfo {
        scene: "the studio's scene".into(),
        key: current.key.clone(),
        algorithm: algorithm.name().into(),
        width: current.size.0,
        height: current.size.1,
        samples_per_pixel: progress.passes,
        seconds: progress.seconds,
        seed: reference_settings(algorithm, 1, 1).seed,
        program_version: env!("CARGO_PKG_VERSION").into(),
    };
    let variance = (progress.passes >= 2).then(|| variance.clone());
    Some(Reference { image: image.clone(), variance, info })
}

impl Drop for References {
    fn drop(&mut self) {
        let _ = self.requests.send(Request::Stop);
        if let Some(store) = self.store.take() {
            // It finishes the request in hand (a file being written) first
            let _ = store.join();
        }
    }
}
