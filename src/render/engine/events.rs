//! What the engine tells its driver, over the session's channel.

use std::sync::Arc;
use std::time::Duration;

use crate::render::film::NoiseEstimate;
use crate::render::image::LinearImage;
use crate::render::integrators::bidir::strategies::StrategyImages;
use crate::render::integrators::bidir::PathPassStats;
use crate::render::integrators::photon_map::PhotonMapStats;
use crate::render::integrators::PhotonPassStats;
use crate::render::world::camera::TileRect;

/// Called after an event is sent, with whether it is news to show at once
/// (`RenderEvent::is_news`) or progress that may wait for the next frame
/// (the studio passes a repaint request).
pub type Notify = Arc<dyn Fn(bool) + Send + Sync>;

#[derive(Clone, Debug)]
pub struct TileUpdate {
    pub generation: u64,
    pub rect: TileRect,
    /// Mean linear radiance, row-major within the tile.
    pub pixels: Vec<[f32; 3]>,
    /// A coarse block-filled preview, not yet part of the estimate.
    pub preview: bool,
    /// Each pixel's estimated variance of its mean, when the job asked
    /// for it (`RenderJob::stream_variance`) and the method keeps it.
    pub variance: Option<Vec<[f32; 3]>>,
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
    /// What each strategy of a bidirectional method has brought so far.
    Strategies {
        generation: u64,
        images: Arc<StrategyImages>,
    },
    Finished {
        generation: u64,
        image: Arc<LinearImage>,
        /// Each pixel's estimated variance of its mean, for unbiased
        /// methods (`Algorithm::is_unbiased`) after two passes.
        variance: Option<Arc<LinearImage>>,
        /// The odd passes' mean alone, where there is a variance: what a
        /// shard carries so that merged shards have one.
        odd: Option<Arc<LinearImage>>,
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
            | RenderEvent::Strategies { generation, .. }
            | RenderEvent::PhotonMaps { generation, .. }
            | RenderEvent::Finished { generation, .. }
            | RenderEvent::Failed { generation, .. } => *generation,
            RenderEvent::Tile(tile) => tile.generation,
        }
    }

    /// Whether the event changes what a viewer should see at once (a job
    /// started, its preview, its end), not just how far a pass has come.
    pub fn is_news(&self) -> bool {
        match self {
            RenderEvent::Tile(tile) => tile.preview,
            RenderEvent::PassFinished { .. } | RenderEvent::Strategies { .. } => false,
            _ => true,
        }
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
    /// Bidirectional work of the last pass.
    pub paths: PathPassStats,
    /// The image's relMSE against the converged image it tends to, from its
    /// own noise: for unbiased methods after two passes.
    pub noise: Option<NoiseEstimate>,
}

impl PassStats {
    pub fn samples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}
