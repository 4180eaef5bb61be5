//! The light vertices as merges find them: a hash grid of their positions
//! (`cells::PointGrid`) and, in the grid's order, what a merge reads of
//! each. A query's candidates then lie in sequence; read from the vertices
//! themselves, each was a cache miss, and most candidates are turned away
//! (on gap-room half lie behind the wall the camera vertex is on): under
//! `perf` those misses were a fifth of a BPM render.

use glam::Vec3;
use rayon::prelude::*;

use super::light_paths::LightPaths;
use super::mis::Partials;
use crate::render::integrators::photon_map::cells::PointGrid;
use crate::scene::Rgb;

/// The grid's cells, in merge radii. A query touches 1 to 8 cells and
/// finds a light vertex or two among a few dozen; measured on gap-room
/// (VCM, 256×192, 16 passes, against the kd-tree): 2 radii 0.95 of the
/// kd-tree's time, 4 radii 0.87–0.89, 8 radii 0.87–0.90, 1 radius 1.18.
const MERGE_CELLS: f32 = 4.0;

/// What a merge reads of a light vertex.
#[derive(Clone, Copy, Debug, Default)]
pub struct MergeVertex {
    /// Toward the vertex before it (the way light came).
    pub wo: Vec3,
    /// Segments from the light.
    pub length: u32,
    pub throughput: Rgb,
    /// Its BSDF's `continuation`: the chance the way back goes on there.
    pub continuation: f32,
    pub partials: Partials,
}

pub struct MergeGrid {
    points: PointGrid,
    /// By slot in the grid's order.
    vertices: Vec<MergeVertex>,
    /// The records and positions in the vertices' order, kept for the
    /// next pass.
    spare: (Vec<MergeVertex>, Vec<Vec3>),
}

/// A grid's arrays, kept from pass to pass: above 32 MiB (VCM at
/// 512×384) each was mapped afresh every pass and its pages faulted in
/// again (`engine::heap`); and what a pass leaves in them is written over,
/// never cleared first (cleared and refilled with defaults, the records
/// were a fifth of the grid's time on gap-room).
#[derive(Default)]
pub struct MergeBuffers {
    by_vertex: Vec<MergeVertex>,
    by_slot: Vec<MergeVertex>,
    positions: Vec<Vec3>,
}

impl MergeGrid {
    /// The grid of `paths`' vertices for merges within `radius` (cells
    /// `MERGE_CELLS` radii wide), in `buffers`.
    pub fn build(paths: &LightPaths, radius: f32, buffers: MergeBuffers) -> Self {
        // The vertices read in sequence here, so that only small records
        // are gathered in the grid's order; each chunk into its own stretch
        let count = paths.chunks.iter().map(|chunk| chunk.vertices.len()).sum();
        let MergeBuffers { by_vertex: mut merged, by_slot: mut vertices, mut positions } = buffers;
        // Every entry below `count` is written below
        merged.truncate(count);
        merged.resize(count, MergeVertex::default());
        positions.truncate(count);
        positions.resize(count, Vec3::ZERO);
        let mut stretches = Vec::with_capacity(paths.chunks.len());
        let (mut positions_left, mut merged_left) = (&mut positions[..], &mut merged[..]);
        for chunk in &paths.chunks {
            let (here, rest) = std::mem::take(&mut positions_left).split_at_mut(chunk.vertices.len());
            let (merged_here, merged_rest) = std::mem::take(&mut merged_left).split_at_mut(chunk.vertices.len());
            stretches.push((chunk, here, merged_here));
            (positions_left, merged_left) = (rest, merged_rest);
        }
        stretches.into_par_iter().for_each(|(chunk, positions, merged)| {
            for (v, (position, merged)) in chunk.vertices.iter().zip(positions.iter_mut().zip(merged)) {
                *position = v.hit.point;
                *merged = MergeVertex {
                    wo: v.wo,
                    length: v.length,
                    throughput: v.throughput,
                    continuation: v.bsdf.continuation(),
                    partials: v.partials,
                };
            }
        });
        let points = PointGrid::build(&positions, |&p| p, radius * MERGE_CELLS);
        points.in_grid_order_into(&merged, &mut vertices);
        Self { points, vertices, spare: (merged, positions) }
    }

    /// Its arrays, for the next pass's grid.
    pub fn into_buffers(self) -> MergeBuffers {
        let (by_vertex, positions) = self.spare;
        MergeBuffers { by_vertex, by_slot: self.vertices, positions }
    }

    /// Every light vertex within `radius` of `point` (squared distance ≤
    /// radius²), in an order fixed by the vertices and the query alone.
    #[inline]
    pub fn for_each_within(&self, point: Vec3, radius: f32, mut f: impl FnMut(&MergeVertex)) {
        self.points.for_each_slot_within(point, radius, |slot| f(&self.vertices[slot]));
    }
}
