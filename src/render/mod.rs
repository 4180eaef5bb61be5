//! The rendering engine: camera, sampling, film, integrators and the
//! progressive tile engine. It knows nothing about any user interface.

pub mod bsdf;
pub mod camera;
pub mod engine;
pub mod image;
pub(crate) mod lanes;
pub mod light;
pub mod occluders;
pub mod path;
pub mod path_lanes;
pub mod rng;
pub mod sampling;
pub mod settings;
pub mod spheres;
pub mod tiles;
pub mod whitted;
pub mod world;

pub use engine::{render_blocking, PassStats, PhotonPassStats, RenderEvent, RenderJob, RenderSession, TileUpdate};
pub use image::LinearImage;
pub use settings::{Algorithm, PhotonSettings, RenderSettings};

/// Work counted per tile and summed per pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    pub rays: u64,
    pub non_finite: u64,
    pub queries: crate::photon::QueryStats,
}
