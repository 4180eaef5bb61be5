//! Rendering, in three layers that depend one way:
//! - `world`: the scene compiled for rendering (flat shapes, lights,
//!   occluders, camera, BSDFs, sampling, the eight-lane math);
//! - `integrators`: the light-transport algorithms, one closed enum, one
//!   file each, with the photon map beside them;
//! - `engine`: jobs, passes over tiles in parallel, the film, sessions and
//!   their events. It knows nothing about any user interface.
//!
//! `settings` (what to render), `film` (what passes add into) and `image`
//! (what comes out) are leaves every layer may use.

pub mod engine;
pub mod film;
pub mod image;
pub mod integrators;
pub mod layers;
pub mod settings;
pub mod unseen;
pub mod world;

pub use engine::{
    render_blocking, render_blocking_on, PassStats, RenderEvent, RenderJob, RenderSession, Switch, TileUpdate, Weight,
    Workers,
};
pub use image::LinearImage;
pub use integrators::PhotonPassStats;
pub use settings::{
    Algorithm, BidirSettings, MergeSettings, Method, MisHeuristic, PhotonSettings, RenderSettings, SppmSettings,
    DEPTH_MEANING,
};
