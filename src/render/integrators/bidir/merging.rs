//! The light vertices as merges find them: a hash grid of their positions
//! (`cells::PointGrid`) and, in the grid's order, what a merge reads of
//! each. A query's candidates then lie in sequence; read from the vertices
//! themselves, each would be a cache miss, and most candidates are turned
//! away (behind the wall the camera vertex is on, say).

use glam::Vec3;
use rayon::prelude::*;

use super::light_paths::{LightPaths, LightVertex};
use super::mis::{Partials, Strategies};
use crate::render::integrators::photon_map::cells::PointGrid;
use crate::scene::Rgb;

/// The grid's cells, in merge radii. A query touches 1 to 8 cells and
/// finds a light vertex or two among a few dozen: smaller cells cost more
/// cells a query, larger ones more candidates (docs/performance.md).
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

/// A grid's arrays, kept from pass to pass: above 32 MiB each would be
/// mapped afresh every pass and its pages faulted in again
/// (`engine::heap`); and what a pass leaves in them is written over, never
/// cleared first.
#[derive(Default)]
pub struct MergeBuffers {
    by_vertex: Vec<MergeVertex>,
    by_slot: Vec<MergeVertex>,
    positions: Vec<Vec3>,
}

impl MergeGrid {
    /// The grid of `paths`' vertices for merges within `radius` (cells
    /// `MERGE_CELLS` radii wide), in `buffers`: those where `strategies`
    /// merge (`Strategies::merges_at`).
    pub fn build(paths: &LightPaths, radius: f32, strategies: &Strategies, buffers: MergeBuffers) -> Self {
        let keep = |v: &&LightVertex| strategies.merges_at(v.after_specular);
        // The vertices read in sequence here, so that only small records
        // are gathered in the grid's order; each chunk into its own stretch.
        // Each chunk counted its vertices that came through a specular one
        let counts: Vec<usize> = (paths.chunks.iter())
            .map(|chunk| match strategies.caustic_merges {
                true => chunk.after_specular as usize,
                false => chunk.vertices.len(),
            })
            .collect();
        let count = counts.iter().sum();
        let MergeBuffers { by_vertex: mut merged, by_slot: mut vertices, mut positions } = buffers;
        // Every entry below `count` is written below
        merged.truncate(count);
        merged.resize(count, MergeVertex::default());
        positions.truncate(count);
        positions.resize(count, Vec3::ZERO);
        let mut stretches = Vec::with_capacity(paths.chunks.len());
        let (mut positions_left, mut merged_left) = (&mut positions[..], &mut merged[..]);
        // A chunk with nothing to keep is not read
        for (chunk, &count) in paths.chunks.iter().zip(&counts).filter(|(_, &count)| count > 0) {
            let (here, rest) = std::mem::take(&mut positions_left).split_at_mut(count);
            let (merged_here, merged_rest) = std::mem::take(&mut merged_left).split_at_mut(count);
            stretches.push((chunk, here, merged_here));
            (positions_left, merged_left) = (rest, merged_rest);
        }
        stretches.into_par_iter().for_each(|(chunk, positions, merged)| {
            for (v, (position, merged)) in chunk.vertices.iter().filter(keep).zip(positions.iter_mut().zip(merged)) {
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

    /// Whether it holds no vertex (no query can find one).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Every light vertex within `radius` of `point` (squared distance ≤
    /// radius²), in an order fixed by the vertices and the query alone.
    #[inline]
    pub fn for_each_within(&self, point: Vec3, radius: f32, mut f: impl FnMut(&MergeVertex)) {
        self.points.for_each_slot_within(point, radius, |slot| f(&self.vertices[slot]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::bidir::light_paths;
    use crate::render::integrators::bidir::Context;
    use crate::render::integrators::photon_map::emit::LightPicker;
    use crate::render::settings::MisHeuristic;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::World;
    use crate::scene::presets;

    /// On the caustic preset, a grid of caustic merges holds exactly the
    /// light vertices light came to through the glass or a mirror (some,
    /// not all, none fewer than two segments from the light); the full
    /// grid holds every vertex. Each vertex is found by a query at its own
    /// position, and only those the grid holds.
    #[test]
    fn caustic_merges_keep_the_vertices_light_came_to_through_a_specular_one() {
        let (width, height) = (40, 30);
        let scene = presets::preset("mirror-caustic").and_then(Result::ok).expect("preset");
        let camera = CameraModel::new(&scene.camera, width, height);
        let (world, visible_radius) = World::for_view(&scene, &camera, width, height);
        let picker = LightPicker::new(&world);
        let (pixels, radius) = ((width * height) as f32, visible_radius * 0.01);
        let ctx = Context {
            world: &world,
            lane_world: None,
            camera: &camera,
            strategies: Strategies::with_merges(MisHeuristic::Power, true, true, true, pixels, radius),
            picker: &picker,
            bounds: world.bounds(),
            sky_bounds: world.bounds(),
            background: None,
            max_length: 8,
            light_tracing: false,
            strategy_film: None,
        };
        let paths = light_paths::trace(&ctx, pixels as u64, 0, 3, &|| true).expect("not cancelled");
        let vertices: Vec<&LightVertex> = paths.chunks.iter().flat_map(|chunk| &chunk.vertices).collect();
        let caustic: Vec<&&LightVertex> = vertices.iter().filter(|v| v.after_specular).collect();
        assert!(!caustic.is_empty() && caustic.len() < vertices.len(), "{} of {}", caustic.len(), vertices.len());
        assert!(caustic.iter().all(|v| v.length >= 2));
        let found = |grid: &MergeGrid, v: &LightVertex| {
            let mut found = false;
            grid.for_each_within(v.hit.point, radius, |m| found |= m.wo == v.wo && m.length == v.length);
            found
        };
        let everywhere = Strategies::new(MisHeuristic::Power, true, true, pixels, radius);
        let full = MergeGrid::build(&paths, radius, &everywhere, MergeBuffers::default());
        assert_eq!(full.points.len(), vertices.len());
        assert!(vertices.iter().all(|v| found(&full, v)));
        let caustics = MergeGrid::build(&paths, radius, &ctx.strategies, full.into_buffers());
        assert_eq!(caustics.points.len(), caustic.len());
        assert!(vertices.iter().all(|v| found(&caustics, v) == v.after_specular));
    }
}
