//! The photon map: photons traced from the lights into Jensen's global and
//! caustic maps on our own kd-tree, their radiance estimate, and map files;
//! and the hash grid that SPPM's gathers and VCM's merges search instead.

pub mod cells;
mod direction;
pub mod emit;
pub mod file;
mod flight;
mod flight_lanes;
pub mod grid;
pub mod kdtree;
pub mod maps;
pub mod record;
pub mod trace;

pub use kdtree::{Neighbours, PhotonKdTree};
pub use maps::{PhotonMapStats, PhotonMaps, QueryStats};
pub use record::Photon;
