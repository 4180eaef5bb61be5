//! Photon tracing: photons leave the lights, bounce by their surfaces' BSDFs
//! with Russian roulette at diffuse surfaces, and are stored at non-specular
//! hits according to which map they are for. Photon i's random stream is
//! fixed by (i, pass, seed), and chunks are joined in order, so the maps do
//! not depend on the thread count. Eight photons are traced at a time
//! where the CPU and the world allow (`trace_lanes`), with the same bits.

use rayon::prelude::*;

pub use super::flight::MapKind;
use super::flight::Tracing;
use super::record::Photon;
use super::trace_lanes;
use crate::render::integrators::path_lanes::PathLanes;
use crate::render::world::World;

/// Photons a task traces: the unit of work a cancel waits for at most.
pub const CHUNK: u64 = 4096;

/// Trace `count` photons for `kind`; stored powers are divided by `count`.
pub fn trace_photons(world: &World, kind: MapKind, count: u64, pass: u64, seed: u64, max_depth: u32) -> Vec<Photon> {
    trace_photons_until(world, kind, count, pass, seed, max_depth, &|| true).unwrap_or_default()
}

/// `trace_photons`, asking `keep_going` before each chunk of photons: None
/// once it says no, after no more than the chunks already being traced
/// (one a worker).
pub fn trace_photons_until(
    world: &World,
    kind: MapKind,
    count: u64,
    pass: u64,
    seed: u64,
    max_depth: u32,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Option<Vec<Photon>> {
    let Some(tracing) = Tracing::new(world, kind, count, pass, seed, max_depth) else {
        return Some(Vec::new());
    };
    // Built once for all the chunks: None where the CPU or the world has no lanes
    let lanes = PathLanes::new(world).filter(|_| PathLanes::runs_in_lanes());
    // usize: rayon splits only ranges of usize by index
    let chunks = count.div_ceil(CHUNK) as usize;
    let per_chunk: Option<Vec<Vec<Photon>>> = (0..chunks)
        .into_par_iter()
        .with_max_len(1) // balanced by chunk, as the passes are by tile
        .map(|chunk| {
            if !keep_going() {
                return None;
            }
            let chunk = chunk as u64;
            let indices = chunk * CHUNK..((chunk + 1) * CHUNK).min(count);
            Some(match &lanes {
                Some(lanes) => trace_lanes::trace_chunk(lanes, &tracing, indices),
                None => tracing.trace_one_by_one(indices),
            })
        })
        .collect();
    Some(per_chunk?.concat())
}
