//! A viewport pane: its own render session and settings, the linear image
//! assembled from the engine's tiles, and the texture showing it. The
//! engine bridge (`PaneState::apply`) is a plain function of events, so it
//! is tested without a window.

use std::sync::Arc;
use std::time::Duration;

use eframe::egui;

use crate::analysis::metrics::{rel_mse, RelMseOptions};
use crate::render::image::tonemap_srgb8;
use crate::render::integrators::photon_map::PhotonMapStats;
use crate::render::world::camera::TileRect;
use crate::render::{Algorithm, LinearImage, PassStats, RenderEvent, RenderJob, RenderSession, RenderSettings};
use crate::scene::Scene;

/// One point of a pane's convergence history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassRecord {
    pub passes: u32,
    pub seconds: f64,
    pub pass_seconds: f64,
    pub samples_per_second: f64,
    /// relMSE against the reference, when there is one.
    pub error: Option<f64>,
    /// SPPM's mean gather radius after the pass.
    pub sppm_radius: Option<f32>,
}

/// What a pane knows about its current job, fed only by engine events.
#[derive(Clone, Debug)]
pub struct PaneState {
    pub generation: u64,
    pub image: LinearImage,
    /// Tiles changed since the texture was last updated.
    pub dirty: Vec<TileRect>,
    pub stats: Option<PassStats>,
    pub history: Vec<PassRecord>,
    pub maps: Option<PhotonMapStats>,
    pub failed: Option<String>,
    pub finished: bool,
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
        }
    }

    /// Apply one engine event. Events of any other generation (a job that
    /// was restarted) are dropped: their tiles never reach the texture.
    /// Returns whether anything changed.
    pub fn apply(&mut self, event: RenderEvent, reference: Option<&LinearImage>) -> bool {
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
                self.dirty.push(rect);
            }
            RenderEvent::PhotonMaps { stats, .. } => self.maps = Some(stats),
            RenderEvent::PassFinished { stats, .. } => {
                let error = reference.and_then(|r| {
                    let comparable = self.image.at_size(r.width, r.height)?;
                    rel_mse(&comparable, r, RelMseOptions::default()).ok()
                });
                self.history.push(PassRecord {
                    passes: stats.passes,
                    seconds: stats.elapsed.as_secs_f64(),
                    pass_seconds: stats.pass_time.as_secs_f64(),
                    samples_per_second: stats.samples_per_second(),
                    error,
                    sppm_radius: (stats.photon.mean_radius > 0.0).then_some(stats.photon.mean_radius),
                });
                self.stats = Some(stats);
            }
            RenderEvent::Finished { stats, .. } => {
                self.stats = Some(stats);
                self.finished = true;
            }
            RenderEvent::Failed { message, .. } => self.failed = Some(message),
        }
        true
    }

    pub fn passes(&self) -> u32 {
        self.stats.map_or(0, |s| s.passes)
    }

    pub fn latest_error(&self) -> Option<f64> {
        self.history.last().and_then(|r| r.error)
    }
}

pub struct Pane {
    pub settings: RenderSettings,
    pub exposure: f32,
    pub state: PaneState,
    /// None when the OS refused the worker thread (said in `state.failed`).
    session: Option<RenderSession>,
    texture: Option<egui::TextureHandle>,
}

impl Pane {
    pub fn new(ctx: &egui::Context, settings: RenderSettings) -> Self {
        let repaint = ctx.clone();
        let mut state = PaneState::new(0, settings.width, settings.height);
        let session = match RenderSession::new(Some(Arc::new(move || repaint.request_repaint()))) {
            Ok(session) => Some(session),
            Err(e) => {
                state.failed = Some(format!("could not start this pane's render worker: {e}"));
                None
            }
        };
        Self { state, settings, exposure: 0.0, session, texture: None }
    }

    pub fn algorithm(&self) -> Algorithm {
        self.settings.algorithm()
    }

    /// Abandon the current job and render `scene` afresh (never waits).
    pub fn restart(&mut self, scene: Arc<Scene>) {
        let Some(session) = &self.session else { return };
        let generation = session.start(RenderJob::new(scene, self.settings.clone()));
        self.state = PaneState::new(generation, self.settings.width, self.settings.height);
    }

    pub fn pause(&mut self) {
        if let Some(session) = &self.session {
            session.cancel();
        }
    }

    /// Take every waiting event without blocking.
    pub fn poll(&mut self, reference: Option<&LinearImage>) -> bool {
        let Some(session) = &self.session else { return false };
        let mut changed = false;
        loop {
            match session.events().try_recv() {
                Ok(event) => changed |= self.state.apply(event, reference),
                Err(crossbeam_channel::TryRecvError::Empty) => return changed,
                Err(crossbeam_channel::TryRecvError::Disconnected) => {
                    self.state.failed = Some("this pane's render worker stopped".into());
                    self.session = None;
                    return true;
                }
            }
        }
    }

    /// Bring the texture up to date: only the tiles that changed are
    /// uploaded, the whole image only when the size or exposure changed.
    pub fn texture(&mut self, ctx: &egui::Context) -> &egui::TextureHandle {
        let image = &self.state.image;
        let size = [image.width as usize, image.height as usize];
        let options = egui::TextureOptions::LINEAR;
        let stale = self.texture.as_ref().is_none_or(|t| t.size() != size);
        if stale {
            let rgba = image.to_rgba8(self.exposure);
            let full = egui::ColorImage::from_rgba_unmultiplied(size, &rgba);
            self.texture = Some(ctx.load_texture("pane", full, options));
            self.state.dirty.clear();
        }
        let texture =
            self.texture.get_or_insert_with(|| ctx.load_texture("pane", egui::ColorImage::example(), options));
        for rect in self.state.dirty.drain(..) {
            let mut rgb = Vec::with_capacity((rect.width * rect.height * 3) as usize);
            for y in rect.y..rect.y + rect.height {
                for x in rect.x..rect.x + rect.width {
                    rgb.extend_from_slice(&tonemap_srgb8(image.get(x, y), self.exposure));
                }
            }
            let tile = egui::ColorImage::from_rgb([rect.width as usize, rect.height as usize], &rgb);
            texture.set_partial([rect.x as usize, rect.y as usize], tile, options);
        }
        texture
    }

    /// Re-tone-map everything (after an exposure change).
    pub fn refresh_texture(&mut self) {
        self.texture = None;
    }

    /// "Path tracing · 64 spp · 3.2 s · 2.1 M samples/s · relMSE 1.3e-3"
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
        label += &match self.state.latest_error() {
            Some(e) => format!(" · relMSE {e:.2e}"),
            None => " · relMSE —".to_owned(),
        };
        label
    }

    pub fn elapsed(&self) -> Duration {
        self.state.stats.map_or(Duration::ZERO, |s| s.elapsed)
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
        })
    }

    #[test]
    fn tiles_of_an_abandoned_generation_never_reach_the_image() {
        // A restart made generation 2 current while generation 1's pass was
        // still in flight: its late tiles must be dropped.
        let mut state = PaneState::new(2, 4, 4);
        assert!(!state.apply(tile(1, 9.0), None));
        assert!(state.dirty.is_empty());
        assert!(state.image.pixels.iter().all(|p| *p == [0.0; 3]));
        assert!(state.apply(tile(2, 0.5), None));
        assert_eq!(state.image.get(1, 1), [0.5; 3]);
        assert_eq!(state.dirty.len(), 1);
        assert!(!state.apply(RenderEvent::Failed { generation: 1, message: "old".into() }, None));
        assert!(state.failed.is_none());
    }
}
