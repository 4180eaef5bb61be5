//! Path tracing eight paths at a time on the world compiled for the lanes
//! (`world::lane_world::LaneWorld`): the shading, the materials and light
//! sampling run in the same lanes as the hit loop, and a lane whose path
//! ends takes the next sample, so lanes stay busy however long the paths
//! are.
//!
//! It is `path::radiance` lane by lane, not an approximation of it: the
//! same operations in the same order on the same random streams, so the
//! image is bit for bit the scalar one (`tests/path_lanes.rs` checks it).
//! Rare cases call the scalar code for that lane: a BSDF-sampled ray
//! reaching a light, the background sampled as a light.
//!
//! In `bounce` a bounce of eight paths and the loop around it, in `state`
//! the paths in flight, in `samples` a tile's camera samples.

mod bounce;
mod samples;
mod state;

pub use bounce::radiance;
