//! A viewport pane: its own render session and settings, the linear image
//! assembled from the engine's tiles, and the texture showing it. The
//! engine bridge (`PaneState::apply`) is a plain function of events, so it
//! is tested without a window.

use std::sync::Arc;
use std::time::Duration;

use eframe::egui;

use super::strategies::{strategies_ui, StrategyView};
use super::widgets::{number, slider};
use crate::analysis::metrics::{rel_mse_against, ErrorEstimate};
use crate::analysis::reference::Reference;
use crate::limits;
use crate::render::film::NoiseEstimate;
use crate::render::image::Tonemap;
use crate::render::integrators::bidir::strategies::StrategyImages;
use crate::render::integrators::photon_map::PhotonMapStats;
use crate::render::unseen::unseen_lights;
use crate::render::world::camera::TileRect;
use crate::render::{
    Algorithm, LinearImage, Method, MisHeuristic, PassStats, RenderEvent, RenderJob, RenderSession, RenderSettings,
    Switch, Workers, DEPTH_MEANING,
};
use crate::scene::ValidScene;

/// Pixels of changed tiles a pane shows per frame at most (a 320×240
/// pane's whole image in two frames).
const UPLOAD_PIXELS_PER_FRAME: usize = 40_000;

/// One point of a pane's convergence history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassRecord {
    pub passes: u32,
    pub seconds: f64,
    pub pass_seconds: f64,
    pub samples_per_second: f64,
    /// How wrong the image was after the pass, if that can be said.
    pub error: Option<PaneError>,
    /// SPPM's mean gather radius after the pass.
    pub sppm_radius: Option<f32>,
}

/// How wrong a pane's image is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PaneError {
    /// relMSE against the reference, its noise taken out.
    Measured(ErrorEstimate),
    /// relMSE estimated from the image's own noise (an unbiased method,
    /// while there is no reference to compare with).
    Estimated(NoiseEstimate),
    /// Below this, the most a reference still too rough to measure it can
    /// say (a biased method, whose image says nothing of its own error).
    Below(f64),
}

impl PaneError {
    pub fn rel_mse(&self) -> f64 {
        match self {
            PaneError::Measured(e) => e.rel_mse,
            PaneError::Estimated(e) => e.rel_mse,
            PaneError::Below(bound) => *bound,
        }
    }

    pub fn standard_error(&self) -> f64 {
        match self {
            PaneError::Measured(e) => e.standard_error,
            PaneError::Estimated(e) => e.standard_error,
            PaneError::Below(_) => 0.0,
        }
    }
}

/// What a pane knows about its current job, fed only by engine events.
#[derive(Clone, Debug)]
pub struct PaneState {
    pub generation: u64,
    pub image: LinearImage,
    /// Tiles changed since the texture last showed them, each once, oldest
    /// first: a tile that changes again keeps its place, so every tile is
    /// shown within a few frames however fast passes come.
    pub dirty: Vec<TileRect>,
    pub stats: Option<PassStats>,
    pub history: Vec<PassRecord>,
    pub maps: Option<PhotonMapStats>,
    pub failed: Option<String>,
    pub finished: bool,
    /// What each strategy brought, for a bidirectional pane whose view is open.
    pub strategies: Option<Arc<StrategyImages>>,
    /// When (seconds into the job) the error was last measured.
    measured_at: f64,
}

impl PaneState {
    pub fn new(generation: u64, width: u32, height: u32) -> Self {
        Self {
            generation,
            image: LinearImage::new(width, height),
            dirty: Vec::new(),
            stats: None,
            history: Vec::new(),
            maps: None,
            failed: None,
            finished: false,
            strategies: None,
            measured_at: 0.0,
        }
    }

    /// Apply one engine event. Events of any other generation (a job that
    /// was restarted) are dropped: their tiles never reach the texture. A
    /// finished pass is measured against `reference` (or by its own noise)
    /// only if `measure`. Returns whether anything changed.
    pub fn apply(&mut self, event: RenderEvent, reference: Option<&Reference>, measure: bool) -> bool {
        if event.generation() != self.generation {
            return false;
        }
        match event {
            RenderEvent::Started { width, height, .. } => {
                if (width, height) != (self.image.width, self.image.height) {
                    self.image = LinearImage::new(width, height);
                }
            }
            RenderEvent::Tile(tile) => {
                let rect = tile.rect;
                if rect.x + rect.width > self.image.width || rect.y + rect.height > self.image.height {
                    return false;
                }
                for (i, pixel) in tile.pixels.into_iter().enumerate() {
                    let (x, y) = (rect.x + i as u32 % rect.width, rect.y + i as u32 / rect.width);
                    self.image.pixels[(y * self.image.width + x) as usize] = pixel;
                }
                if !self.dirty.contains(&rect) {
                    self.dirty.push(rect);
                }
            }
            RenderEvent::PhotonMaps { stats, .. } => self.maps = Some(stats),
            RenderEvent::PassFinished { stats, .. } => {
                // Measured at ten points a decade of time (and at every one
                // of the first passes): a log–log plot needs no more, and
                // each measure costs the UI thread a pass over the image
                let seconds = stats.elapsed.as_secs_f64();
                let due = stats.passes <= 8 || seconds >= self.measured_at * 10f64.powf(0.1);
                let error = if measure && due {
                    self.measured_at = seconds;
                    self.error(&stats, reference)
                } else {
                    None
                };
                self.history.push(PassRecord {
                    passes: stats.passes,
                    seconds,
                    pass_seconds: stats.pass_time.as_secs_f64(),
                    samples_per_second: stats.samples_per_second(),
                    error,
                    sppm_radius: (stats.photon.mean_radius > 0.0).then_some(stats.photon.mean_radius),
                });
                self.stats = Some(stats);
            }
            RenderEvent::Finished { stats, .. } => {
                // The final image is always measured
                if self.history.last().is_some_and(|r| r.error.is_none()) {
                    let error = self.error(&stats, reference);
                    if let Some(last) = self.history.last_mut() {
                        last.error = error;
                    }
                }
                self.stats = Some(stats);
                self.finished = true;
            }
            RenderEvent::Strategies { images, .. } => self.strategies = Some(images),
            RenderEvent::Failed { message, .. } => self.failed = Some(message),
        }
        true
    }

    /// The image's error after the pass `stats` reports: measured against
    /// `reference`, else estimated from its own noise.
    fn error(&self, stats: &PassStats, reference: Option<&Reference>) -> Option<PaneError> {
        let measured = reference.and_then(|r| {
            let comparable = self.image.at_size(r.image.width, r.image.height)?;
            rel_mse_against(&comparable, r).ok()
        });
        let bound = measured.and_then(|e| e.noise_floor).map(|floor| PaneError::Below(floor / NOISE_OVER_ERROR));
        let measured = measured.filter(measurable).map(PaneError::Measured);
        measured.or(stats.noise.map(PaneError::Estimated)).or(bound)
    }

    pub fn passes(&self) -> u32 {
        self.stats.map_or(0, |s| s.passes)
    }

    /// The error last measured (passes in between are not).
    pub fn latest_error(&self) -> Option<PaneError> {
        self.latest_measure().map(|(_, error)| error)
    }

    /// The error last measured and the pass it was measured after.
    pub fn latest_measure(&self) -> Option<(u32, PaneError)> {
        self.history.iter().rev().find_map(|r| r.error.map(|e| (r.passes, e)))
    }
}

/// How much noisier than the error it measures a reference still being
/// made may be: the correction takes the reference's noise off the raw
/// figure, and where that noise is many times the error left, what is left
/// is mostly the noise of that correction (docs/performance.md, session 31).
const NOISE_OVER_ERROR: f64 = 3.0;

/// Whether a figure measured against a reference says the pane's error:
/// the reference converged (no noise to take off) or its noise is at most
/// `NOISE_OVER_ERROR` times the error.
fn measurable(estimate: &ErrorEstimate) -> bool {
    match estimate.noise_floor {
        None => true,
        Some(floor) => estimate.rel_mse > 0.0 && floor <= NOISE_OVER_ERROR * estimate.rel_mse,
    }
}

pub struct Pane {
    settings: RenderSettings,
    exposure: f32,
    state: PaneState,
    /// None when the OS refused its thread (said in `state.failed`).
    session: Option<RenderSession>,
    texture: Option<egui::TextureHandle>,
    /// Whether the texture magnifies its pixels as squares.
    texture_nearest: bool,
    strategy_view: StrategyView,
    /// On while the strategy view is open; every job of the pane reads it.
    strategies: Switch,
    /// What the pane's algorithm cannot show of the scene (`unseen`).
    warning: Option<String>,
}

impl Pane {
    /// A pane rendering on `workers` (shared with the other panes; None if
    /// the OS refused them, which the pane then says).
    pub fn new(ctx: &egui::Context, workers: Option<&Workers>, settings: RenderSettings, exposure: f32) -> Self {
        let repaint = ctx.clone();
        let mut state = PaneState::new(0, settings.width, settings.height);
        let notify: crate::render::engine::Notify = Arc::new(move |news| super::status::repaint(&repaint, news));
        let session = match workers.map(|w| RenderSession::new(w, Some(notify))) {
            Some(Ok(session)) => Some(session),
            Some(Err(e)) => {
                state.failed = Some(format!("could not start this pane's render thread: {e}"));
                None
            }
            None => {
                state.failed = Some("the render threads could not start".into());
                None
            }
        };
        let (strategy_view, strategies) = (StrategyView::default(), Switch::default());
        Self {
            state,
            settings,
            exposure,
            session,
            texture: None,
            texture_nearest: false,
            strategy_view,
            strategies,
            warning: None,
        }
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The settings, to change; the pane renders with them at its next restart.
    pub fn settings_mut(&mut self) -> &mut RenderSettings {
        &mut self.settings
    }

    pub fn state(&self) -> &PaneState {
        &self.state
    }

    pub fn exposure(&self) -> f32 {
        self.exposure
    }

    pub fn algorithm(&self) -> Algorithm {
        self.settings.algorithm()
    }

    /// Whether its algorithm has strategies to show (the bidirectional ones).
    pub fn has_strategies(&self) -> bool {
        self.algorithm().is_bidirectional()
    }

    pub fn strategy_view_mut(&mut self) -> &mut StrategyView {
        &mut self.strategy_view
    }

    /// The strategy window, while it is open.
    pub fn strategies_ui(&mut self, ctx: &egui::Context, index: usize) {
        let light = self.state.image.mean();
        let pane_light = (light[0] + light[1] + light[2]) / 3.0;
        let images = self.state.strategies.clone();
        strategies_ui(ctx, index, &mut self.strategy_view, images, self.exposure, pane_light);
        // Its window may have been closed
        self.strategies.set(self.strategy_view.open);
    }

    /// Open or close the strategy view: the job going on counts each
    /// strategy from its next pass, or stops counting (no restart).
    pub fn show_strategies(&mut self, open: bool) {
        self.strategy_view.open = open;
        self.strategies.set(open);
    }

    /// Abandon the current job and render `scene` afresh (never waits).
    pub fn restart(&mut self, scene: Arc<ValidScene>) {
        let unseen = unseen_lights(&scene, self.algorithm());
        self.warning = (!unseen.is_empty()).then(|| unseen.join("; "));
        let Some(session) = &self.session else { return };
        let strategies = self.strategies.clone();
        let job = RenderJob { estimate_noise: true, strategies, ..RenderJob::new(scene, self.settings.clone()) };
        let generation = session.start(job);
        self.state = PaneState::new(generation, self.settings.width, self.settings.height);
    }

    /// What the pane's algorithm cannot show of its scene, if anything.
    pub fn warning(&self) -> Option<&str> {
        self.warning.as_deref()
    }

    pub fn pause(&mut self) {
        if let Some(session) = &self.session {
            session.cancel();
        }
    }

    /// Take every waiting event without blocking. relMSE is measured for
    /// the newest pass among them only: a fast method finishes several
    /// passes a frame, and measuring each on the UI thread cost frames
    /// milliseconds apiece.
    pub fn poll(&mut self, reference: Option<&Reference>) -> bool {
        let Some(session) = &self.session else { return false };
        let mut events = Vec::new();
        let disconnected = loop {
            match session.events().try_recv() {
                Ok(event) => events.push(event),
                Err(crossbeam_channel::TryRecvError::Empty) => break false,
                Err(crossbeam_channel::TryRecvError::Disconnected) => break true,
            }
        };
        let newest_pass = events.iter().rposition(|e| matches!(e, RenderEvent::PassFinished { .. }));
        let mut changed = false;
        for (i, event) in events.into_iter().enumerate() {
            changed |= self.state.apply(event, reference, Some(i) == newest_pass);
        }
        if disconnected {
            self.state.failed = Some("this pane's render worker stopped".into());
            self.session = None;
            return true;
        }
        changed
    }

    /// Bring the texture up to date: only the tiles that changed are
    /// uploaded, the whole image only when the size or exposure changed.
    /// A frame uploads at most `UPLOAD_PIXELS_PER_FRAME` of the changed
    /// tiles' pixels and asks for another frame for the rest: a frame that
    /// found whole passes of four panes waiting would otherwise take tens of
    /// milliseconds.
    /// The texture as it is, for another pane to draw (a wipe).
    pub fn texture_id(&self) -> Option<egui::TextureId> {
        self.texture.as_ref().map(|t| t.id())
    }

    /// `nearest`: pixels magnified as squares (looking closely), else blended.
    pub fn texture(&mut self, ctx: &egui::Context, nearest: bool) -> &egui::TextureHandle {
        let image = &self.state.image;
        let size = [image.width as usize, image.height as usize];
        let options = match nearest {
            true => {
                egui::TextureOptions { magnification: egui::TextureFilter::Nearest, ..egui::TextureOptions::LINEAR }
            }
            false => egui::TextureOptions::LINEAR,
        };
        let tonemap = Tonemap::new(self.exposure);
        let stale = self.texture.as_ref().is_none_or(|t| t.size() != size) || self.texture_nearest != nearest;
        if stale {
            self.texture_nearest = nearest;
            let rgba = image.to_rgba8(self.exposure);
            let full = egui::ColorImage::from_rgba_unmultiplied(size, &rgba);
            self.texture = Some(ctx.load_texture("pane", full, options));
            self.state.dirty.clear();
        }
        let texture =
            self.texture.get_or_insert_with(|| ctx.load_texture("pane", egui::ColorImage::example(), options));
        let mut budget = UPLOAD_PIXELS_PER_FRAME;
        let mut uploaded = 0;
        for rect in &self.state.dirty {
            if budget < rect.pixels() && uploaded > 0 {
                break;
            }
            budget = budget.saturating_sub(rect.pixels());
            uploaded += 1;
            let mut pixels = Vec::with_capacity(rect.pixels());
            for y in rect.y..rect.y + rect.height {
                let row = (y * image.width) as usize;
                for p in &image.pixels[row + rect.x as usize..row + (rect.x + rect.width) as usize] {
                    let [r, g, b] = tonemap.pixel(*p);
                    pixels.push(egui::Color32::from_rgb(r, g, b));
                }
            }
            let tile = egui::ColorImage::new([rect.width as usize, rect.height as usize], pixels);
            texture.set_partial([rect.x as usize, rect.y as usize], tile, options);
        }
        self.state.dirty.drain(..uploaded);
        if !self.state.dirty.is_empty() {
            super::status::repaint(ctx, false);
        }
        texture
    }

    /// Re-tone-map everything (after an exposure change).
    pub fn refresh_texture(&mut self) {
        self.texture = None;
    }

    /// "Path tracing · 64 spp · 3.2 s · 2.1 M samples/s · relMSE 1.3e-3 ±2e-5";
    /// "≈1.3e-3 (own noise)" while there is no reference; "needs a
    /// reference" for a biased method without one.
    pub fn label(&self) -> String {
        let mut label = self.algorithm().label().to_owned();
        if let Some(stats) = &self.state.stats {
            label += &format!(
                " · {} spp · {:.1} s · {:.2} M samples/s",
                stats.passes,
                stats.elapsed.as_secs_f64(),
                stats.samples_per_second() / 1e6
            );
        }
        let measure = self.state.latest_measure();
        label += &match measure.map(|(_, error)| error) {
            Some(PaneError::Measured(e)) => format!(" · relMSE {:.2e} ±{:.0e}", e.rel_mse, e.standard_error),
            Some(PaneError::Estimated(e)) => format!(" · relMSE ≈{:.2e} (own noise)", e.rel_mse),
            Some(PaneError::Below(bound)) => format!(" · relMSE <{bound:.1e} (the reference is too rough to tell)"),
            None if !self.algorithm().is_unbiased() => " · relMSE — (needs a reference)".to_owned(),
            None => " · relMSE —".to_owned(),
        };
        // Measured now and then: say when, if not after the last pass
        if let Some((passes, _)) = measure.filter(|(passes, _)| *passes != self.state.passes()) {
            label += &format!(" at {passes} spp");
        }
        label
    }

    pub fn elapsed(&self) -> Duration {
        self.state.stats.map_or(Duration::ZERO, |s| s.elapsed)
    }
}

impl Pane {
    /// The pane's settings, only the knobs of its algorithm; returns
    /// whether the pane must restart.
    pub fn settings_ui(&mut self, ui: &mut egui::Ui) -> bool {
        let before = self.settings.clone();
        let s = &mut self.settings;
        // The engine's limits, narrowed where a pane cannot use more
        let range = |limit: limits::Limit<u32>| limit.min..=limit.max;
        let mut spp = s.samples_per_pixel.unwrap_or(0);
        let target = number(&mut spp).range(0..=limits::SAMPLES_PER_PIXEL.max);
        ui.add(target.prefix("spp target (0: none) "));
        s.samples_per_pixel = (spp > 0).then_some(spp);
        let mut budget = s.time_limit.unwrap_or(0.0);
        let time = number(&mut budget).range(0.0..=limits::SECONDS.max).speed(0.5);
        ui.add(time.prefix("time budget s (0: none) "));
        s.time_limit = (budget > 0.0).then_some(budget);
        ui.add(number(&mut s.max_depth).range(range(limits::MAX_DEPTH)).prefix("max depth "))
            .on_hover_text(DEPTH_MEANING);
        ui.add(number(&mut s.width).range(16..=4096).prefix("width "));
        ui.add(number(&mut s.height).range(16..=4096).prefix("height "));
        let mis_ui = |ui: &mut egui::Ui, mis: &mut MisHeuristic| {
            ui.horizontal(|ui| {
                ui.label("MIS");
                ui.radio_value(mis, MisHeuristic::Power, "power");
                ui.radio_value(mis, MisHeuristic::Balance, "balance");
            });
        };
        let vcm = matches!(s.method, Method::Vcm(_));
        match &mut s.method {
            Method::Whitted | Method::Path | Method::LightTracing => {}
            Method::Bdpt(b) => {
                ui.separator();
                mis_ui(ui, &mut b.mis);
            }
            Method::Bpm(m) | Method::Vcm(m) => {
                ui.separator();
                mis_ui(ui, &mut m.mis);
                let radius = number(&mut m.radius).range(0.0..=1e6).speed(0.001);
                ui.add(radius.prefix("merge radius (0: auto) "));
                ui.add(slider(&mut m.alpha, 0.05..=1.0).text("α"));
                if vcm {
                    let caustics = ui.checkbox(&mut m.caustic_merges, "merge caustic paths only");
                    caustics.on_hover_text(
                        "Merge only where light came through a mirror or glass; connections make every other path",
                    );
                }
            }
            Method::Photon(p) => {
                ui.separator();
                let photons = range(limits::PHOTONS);
                let global = number(&mut p.global_photons).range(photons.clone()).speed(1000);
                ui.add(global.prefix("global photons "));
                let caustic = number(&mut p.caustic_photons).range(photons).speed(1000);
                ui.add(caustic.prefix("caustic photons "));
                ui.add(number(&mut p.k_nearest).range(8..=1000).prefix("k nearest "));
                let radius = number(&mut p.max_radius).range(0.0..=1e6).speed(0.001);
                ui.add(radius.prefix("max radius (0: auto) "));
                ui.checkbox(&mut p.final_gather, "final gather");
                ui.add(number(&mut p.final_gather_rays).range(1..=1024).prefix("gather rays "));
            }
            Method::Sppm(p) => {
                ui.separator();
                let photons = number(&mut p.photons_per_pass).range(range(limits::SPPM_PHOTONS));
                ui.add(photons.speed(1000).prefix("photons per pass "));
                let radius = number(&mut p.initial_radius).range(0.0..=1e6).speed(0.001);
                ui.add(radius.prefix("initial radius (0: auto) "));
                ui.add(slider(&mut p.alpha, 0.05..=1.0).text("α"));
            }
        }
        ui.separator();
        if ui.add(slider(&mut self.exposure, -8.0..=8.0).text("exposure (stops)")).changed() {
            self.refresh_texture();
        }
        self.settings != before
    }

    /// The algorithm chooser; returns whether the algorithm changed.
    pub fn algorithm_ui(&mut self, ui: &mut egui::Ui, index: usize) -> bool {
        let mut algorithm = self.settings.algorithm();
        egui::ComboBox::new(("algorithm", index), format!("pane {}", index + 1))
            .selected_text(algorithm.label())
            .show_ui(ui, |ui| {
                for a in Algorithm::ALL {
                    ui.selectable_value(&mut algorithm, a, a.label());
                }
            });
        if algorithm == self.settings.algorithm() {
            return false;
        }
        self.settings.method = Method::of(algorithm);
        self.settings.max_depth = algorithm.default_max_depth();
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::TileUpdate;

    fn tile(generation: u64, value: f32) -> RenderEvent {
        RenderEvent::Tile(TileUpdate {
            generation,
            rect: TileRect { x: 0, y: 0, width: 2, height: 2 },
            pixels: vec![[value; 3]; 4],
            preview: false,
            variance: None,
        })
    }

    #[test]
    fn tiles_of_an_abandoned_generation_never_reach_the_image() {
        // A restart made generation 2 current while generation 1's pass was
        // still in flight: its late tiles must be dropped.
        let mut state = PaneState::new(2, 4, 4);
        assert!(!state.apply(tile(1, 9.0), None, true));
        assert!(state.dirty.is_empty());
        assert!(state.image.pixels.iter().all(|p| *p == [0.0; 3]));
        assert!(state.apply(tile(2, 0.5), None, true));
        assert_eq!(state.image.get(1, 1), [0.5; 3]);
        assert_eq!(state.dirty.len(), 1);
        assert!(!state.apply(RenderEvent::Failed { generation: 1, message: "old".into() }, None, true));
        assert!(state.failed.is_none());
        // A tile shown again before the texture took it is uploaded once
        assert!(state.apply(tile(2, 0.7), None, true));
        assert_eq!(state.dirty.len(), 1);
    }

    /// A biased pane (no noise of its own to go by) against a reference:
    /// measured while the reference's noise is at most three times the
    /// error, and otherwise said to be below a third of that noise, never
    /// the last figure measured as if it were now's.
    #[test]
    fn a_reference_too_rough_for_the_error_gives_a_bound() {
        use crate::analysis::reference::ReferenceInfo;
        let (width, height) = (16, 12);
        let flat = |value: f32| LinearImage { width, height, pixels: vec![[value; 3]; (width * height) as usize] };
        let info = ReferenceInfo {
            scene: String::new(),
            key: String::new(),
            algorithm: "path".into(),
            width,
            height,
            samples_per_pixel: 64,
            seconds: 1.0,
            seed: 0,
            program_version: String::new(),
        };
        // The pane is 1.1 where the reference is 1: relMSE 0.01/1.01
        let mut state = PaneState::new(1, width, height);
        state.image = flat(1.1);
        let pass = |passes: u32| RenderEvent::PassFinished {
            generation: 1,
            stats: PassStats { passes, elapsed: Duration::from_secs(passes as u64), ..PassStats::default() },
        };
        let quiet = Reference { image: flat(1.0), variance: Some(flat(0.001)), info: info.clone() };
        state.apply(pass(1), Some(&quiet), true);
        let Some(PaneError::Measured(measured)) = state.latest_error() else { panic!("{:?}", state.latest_error()) };
        assert!((measured.rel_mse - (0.01 - 0.001) / 1.01).abs() < 1e-6, "{measured:?}");
        // Noise of 0.05 against an error of 0.01: five times it
        let rough = Reference { image: flat(1.0), variance: Some(flat(0.05)), info };
        state.apply(pass(2), Some(&rough), true);
        let Some(PaneError::Below(bound)) = state.latest_error() else { panic!("{:?}", state.latest_error()) };
        assert!((bound - 0.05 / 1.01 / 3.0).abs() < 1e-6, "{bound}");
    }

    /// A thousand passes over 100 s: the error is measured at every one of
    /// the first eight, then about ten times a decade (not a thousand
    /// times on the UI thread), at the newest pass of a poll only, and
    /// always at the end; the label shows the last one measured.
    #[test]
    fn errors_are_measured_ten_times_a_decade_and_at_the_end() {
        let mut state = PaneState::new(1, 4, 4);
        let noise = Some(NoiseEstimate { rel_mse: 0.5, standard_error: 0.01 });
        let stats = |passes: u32| PassStats {
            passes,
            elapsed: Duration::from_secs_f64(passes as f64 * 0.1),
            noise,
            ..PassStats::default()
        };
        for passes in 1..=1000 {
            let newest_of_poll = passes % 3 == 0 || passes <= 8;
            state.apply(RenderEvent::PassFinished { generation: 1, stats: stats(passes) }, None, newest_of_poll);
        }
        let measured: Vec<u32> = state.history.iter().filter(|r| r.error.is_some()).map(|r| r.passes).collect();
        assert_eq!(measured[..8], [1, 2, 3, 4, 5, 6, 7, 8]);
        // From 0.8 s to 100 s: 2.1 decades
        assert!((25..=32).contains(&measured.len()), "{} measured: {measured:?}", measured.len());
        assert!(measured[8..].iter().all(|p| p % 3 == 0), "only the newest pass of a poll");
        assert!(state.latest_error().is_some());
        let image = Arc::new(LinearImage::new(4, 4));
        let event = RenderEvent::Finished { generation: 1, stats: stats(1000), image, variance: None, odd: None };
        state.apply(event, None, true);
        assert!(state.history.last().unwrap().error.is_some(), "the final image is measured");
    }
}
