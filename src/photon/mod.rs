//! Photon mapping (part of the render layer): photons traced from the lights
//! into Jensen's global and caustic maps on our own kd-tree, radiance
//! estimates from them, and stochastic progressive photon mapping.

pub mod emit;
pub mod file;
pub mod integrator;
pub mod kdtree;
pub mod maps;
pub mod record;
pub mod sppm;
pub mod trace;

pub use kdtree::{Neighbours, PhotonKdTree};
pub use maps::{PhotonMapStats, PhotonMaps, QueryStats};
pub use record::Photon;
