//! The light-transport algorithms, one file each, and what they share.

pub mod next_event;
pub mod path;
pub mod path_lanes;
pub mod photon;
pub mod photon_map;
pub mod sppm;
pub mod whitted;

/// Work counted per tile and summed per pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    pub rays: u64,
    pub non_finite: u64,
    pub queries: photon_map::QueryStats,
}
