//! Light subpaths: one per pixel each pass, from a light chosen in
//! proportion to its power, bouncing by the surfaces' BSDFs with Russian
//! roulette. Each non-specular vertex is kept (for connections and merges)
//! and, where connecting is on, joined to the camera: a splat on the pixel
//! it lands on. Path i's random stream is fixed by (i, pass, seed), and
//! chunks are joined in order, so nothing depends on the thread count.
//! Eight paths are traced at a time (`flying`), and what they make is put
//! back in path order (`reorder`), so nothing depends on how the lanes
//! fell either.

use std::ops::Range;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::mis::{self, Partials};
use super::strategies::{Contribution, PixelTally, Strategy};
use super::Context;
use crate::geometry::{Ray, SurfaceHit};
use crate::render::film::Splat;
use crate::render::integrators::flying::{self, DrawAtHits};
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::shadow_batch::ShadowBatch;
use crate::render::integrators::{reorder, Counters};
use crate::render::world::camera::{CameraConnection, CameraModel};
use crate::render::world::lane_world::{Given, LaneWorld, Want};
use crate::render::world::light::LightSource;
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::occluders::Shadow;
use crate::render::world::rng::Sampler;
use crate::render::world::Hit;
use crate::scene::Rgb;

/// Light paths a task traces: the unit of work a cancel waits for at most.
const CHUNK: u64 = 1024;
/// Keeps light-path streams apart from camera streams with the same indices.
const LIGHT_SALT: u64 = 0x11f3_7a0c_e5b2_d941;

/// A non-specular vertex of a light subpath.
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    pub hit: SurfaceHit,
    /// Toward the vertex before it (the way light came).
    pub wo: Vec3,
    pub bsdf: Bsdf,
    /// Emitted power over the densities so far: what it brings.
    pub throughput: Rgb,
    /// Segments from the light.
    pub length: u32,
    pub partials: Partials,
    /// Whether its subpath started inside every wall (`PathScope::held`).
    pub held: bool,
    /// Whether light came to it through a mirror or glass.
    pub after_specular: bool,
}

impl LightVertex {
    /// The normal on the side light arrived from.
    #[inline]
    pub fn facing(&self) -> Vec3 {
        let n = self.hit.normal;
        if self.wo.dot(n) < 0.0 {
            -n
        } else {
            n
        }
    }
}

/// One pass's light subpaths.
pub struct LightPaths {
    /// The vertices, `CHUNK` paths a chunk as they were traced: joined
    /// into one array, a pass's hundred MB would be copied and their pages
    /// faulted in afresh.
    pub chunks: Vec<PathChunk>,
    /// Joins to the camera, by chunk in the order of the paths.
    pub splats: Vec<Vec<Splat>>,
    /// The same, by strategy, where the strategy view asked for them.
    pub contributions: Vec<Vec<Contribution>>,
    pub counters: Counters,
}

/// The vertices of `CHUNK` paths.
#[derive(Default)]
pub struct PathChunk {
    pub vertices: Vec<LightVertex>,
    /// How many of them light came to through a mirror or glass (only
    /// those merge, by default): counted as they are kept, so a grid of
    /// them knows its size, and passes over a chunk with none, without
    /// reading a vertex.
    pub after_specular: u32,
    /// Where each path's vertices end in `vertices` (they start where the
    /// previous path's end).
    ends: Vec<u32>,
}

impl LightPaths {
    /// The vertices of path `index`.
    #[inline]
    pub fn path(&self, index: usize) -> &[LightVertex] {
        let chunk = &self.chunks[index / CHUNK as usize];
        let index = index % CHUNK as usize;
        let start = if index == 0 { 0 } else { chunk.ends[index - 1] as usize };
        &chunk.vertices[start..chunk.ends[index] as usize]
    }
}

/// Trace `count` light subpaths of pass `pass`, asking `keep_going` before
/// each chunk: None once it says no. Eight at a time where the CPU and the
/// world allow, with the same paths bit for bit.
pub fn trace(
    ctx: &Context,
    count: u64,
    pass: u64,
    seed: u64,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Option<LightPaths> {
    let chunks = count.div_ceil(CHUNK) as usize;
    let per_chunk: Option<Vec<ChunkPaths>> = (0..chunks)
        .into_par_iter()
        .with_max_len(1)
        .map(|chunk| {
            if !keep_going() {
                return None;
            }
            let indices = chunk as u64 * CHUNK..((chunk as u64 + 1) * CHUNK).min(count);
            Some(Flights { ctx, pass, seed }.trace(ctx.lane_world, indices))
        })
        .collect();
    let mut paths =
        LightPaths { chunks: Vec::new(), splats: Vec::new(), contributions: Vec::new(), counters: Counters::default() };
    for chunk in per_chunk? {
        let after_specular = chunk.after_specular;
        paths.chunks.push(PathChunk { vertices: chunk.vertices, after_specular, ends: chunk.ends });
        paths.splats.push(chunk.splats);
        paths.contributions.push(chunk.contributions);
        paths.counters.add(&chunk.counters);
    }
    paths.counters.light_vertices = paths.chunks.iter().map(|chunk| chunk.vertices.len() as u64).sum();
    Some(paths)
}

#[derive(Default)]
struct ChunkPaths {
    vertices: Vec<LightVertex>,
    /// Of `vertices`, those light came to through a mirror or glass.
    after_specular: u32,
    ends: Vec<u32>,
    splats: Vec<Splat>,
    contributions: Vec<Contribution>,
    counters: Counters,
    /// Joins to the camera whose shadow rays are still to trace.
    joins: Joins,
}

/// Joins to the camera, kept until `JOINS` of them are asked for, then
/// their shadow rays traced together and what gets through made splats.
#[derive(Default)]
struct Joins {
    waiting: Vec<Join>,
    shadows: ShadowBatch,
    /// Which path made each splat and contribution made so far: its place
    /// in the chunk.
    splat_places: Vec<u32>,
    contribution_places: Vec<u32>,
}

/// Room reserved per light subpath for the vertices it keeps: a little
/// more than most presets' paths keep (gap-room's 3.25 on average).
const EXPECTED_VERTICES: usize = 4;

/// Joins traced together: a few batches of eight.
const JOINS: usize = 64;

/// A join to the camera whose shadow ray is still to trace: its splat and
/// (for the strategy view) contribution, if nothing blocks it.
struct Join {
    splat: Splat,
    contribution: Option<Contribution>,
    shadow: u32,
    /// Which path made it: its place in the chunk.
    place: u32,
}

impl ChunkPaths {
    /// The waiting joins' shadow rays traced; those that get through
    /// become splats (and contributions), in the order they were made.
    fn trace_joins(&mut self, ctx: &Context) {
        let joins = &mut self.joins;
        joins.shadows.trace(ctx.lane_world, ctx.world);
        for join in joins.waiting.drain(..) {
            if joins.shadows.blocked(join.shadow) {
                continue;
            }
            self.splats.push(join.splat);
            joins.splat_places.push(join.place);
            if let Some(contribution) = join.contribution {
                self.contributions.push(contribution);
                joins.contribution_places.push(join.place);
            }
        }
        joins.shadows.clear();
    }
}

/// One light subpath between its vertices.
struct Flight<'w> {
    sampler: Sampler,
    scope: PathScope<'w>,
    light: &'w LightSource,
    pick: f32,
    /// Where it left the light: the first hit's density by next-event
    /// estimation needs it.
    emitted_at: (Vec3, Vec3),
    ray: Ray,
    throughput: Rgb,
    partials: Partials,
    /// Segments from the light, `ray`'s included.
    length: u32,
    /// Whether it last left a mirror or glass.
    after_specular: bool,
}

/// Light subpaths find how the camera sees their vertices and draw their
/// directions in the lanes where they can.
struct LightDraws<'c, 'w> {
    ctx: &'c Context<'w>,
}

impl DrawAtHits<Flight<'_>> for LightDraws<'_, '_> {
    fn want(&self, path: &Flight) -> Option<Want> {
        let ctx = self.ctx;
        let join = ctx.strategies.connect || ctx.light_tracing;
        // Where `bounce` scatters
        let scatter = path.length + 2 <= ctx.max_length;
        (join || scatter).then(|| Want { state: path.sampler.state(), light: false, join, scatter })
    }

    fn camera(&self) -> Option<&CameraModel> {
        Some(self.ctx.camera)
    }
}

/// The light subpaths of one pass.
struct Flights<'c, 'w> {
    ctx: &'c Context<'w>,
    pass: u64,
    seed: u64,
}

impl<'w> Flights<'_, 'w> {
    /// Path `index`, leaving its light: None if it leaves none.
    fn launch(&self, index: u64) -> Option<Flight<'w>> {
        let ctx = self.ctx;
        let (world, s) = (ctx.world, &ctx.strategies);
        let mut sampler = Sampler::new(index, self.pass, self.seed ^ LIGHT_SALT);
        let (index, pick) = ctx.picker.pick(sampler.next_f32())?;
        let light = &world.lights[index];
        let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
        let emission = light.emit(ctx.bounds_of(light), u1, u2);
        // A light subpath's first vertex is a segment from the light and
        // one more from the camera: shorter paths need none
        if !(emission.pdf > 0.0 && emission.power.is_finite()) || ctx.max_length < 2 {
            return None;
        }
        Some(Flight {
            sampler,
            scope: PathScope::new(world, emission.ray.origin),
            light,
            pick,
            emitted_at: (emission.point, emission.normal),
            ray: emission.ray,
            throughput: emission.power / pick,
            partials: Partials::light(s, emission.pdf * pick, emission.cos, light.is_delta()),
            length: 1,
            after_specular: false,
        })
    }

    /// The path's vertex at `hit`, the nearest along its ray: kept and
    /// joined to the camera unless specular, then scattered, from what it
    /// `drawn` there in the lanes if it did. False once the path ends.
    fn bounce(&self, place: u32, path: &mut Flight, hit: &Hit, drawn: Option<&Given>, out: &mut ChunkPaths) -> bool {
        let ctx = self.ctx;
        let (world, s) = (ctx.world, &ctx.strategies);
        let (light, pick, length) = (path.light, path.pick, path.length);
        let (wo, n) = (-path.ray.direction, hit.surface.normal);
        if length == 1 {
            let direct = light.direct_pdf_a(hit.surface.point, path.emitted_at.0, path.emitted_at.1);
            path.partials.first_hit(s, direct * pick);
        }
        let from_infinity = length == 1 && !light.is_finite();
        let distance2 = hit.surface.t * hit.surface.t;
        path.partials.arrive(s, (!from_infinity).then_some(distance2), wo.dot(n));
        let bsdf = Bsdf::new(world.material_of(hit));
        let sampler = &mut path.sampler;
        if !bsdf.is_specular() {
            let (throughput, partials, held, after_specular) =
                (path.throughput, path.partials, path.scope.held, path.after_specular);
            let vertex = LightVertex { hit: hit.surface, wo, bsdf, throughput, length, partials, held, after_specular };
            if ctx.keeps_vertices() {
                out.vertices.push(vertex);
                out.after_specular += after_specular as u32;
            }
            if s.connect || ctx.light_tracing {
                let seen = match drawn {
                    Some(given) => given.seen,
                    None => {
                        let lens = if ctx.camera.has_lens() { sampler.next_2d() } else { Vec2::ZERO };
                        ctx.camera.connect(vertex.hit.point, lens)
                    }
                };
                join_camera(ctx, &path.scope, &vertex, seen, place, out);
            }
        }
        // A longer path would have no strategy left to finish it
        if length + 2 > ctx.max_length {
            return false;
        }
        let scattered = match drawn {
            Some(given) => given.resume(sampler),
            None => bsdf.sample(wo, n, sampler, Transport::Importance),
        };
        let Some(scattered) = scattered else { return false };
        let go_on = bsdf.continuation();
        if sampler.next_f32() >= go_on {
            return false;
        }
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let reverse = if scattered.delta { scattered.pdf } else { bsdf.pdf(scattered.wi, wo, facing) };
        let merges_here = s.merges_at(path.after_specular);
        // A light subpath knows at once whether a merge here is a strategy,
        // so nothing is left behind to count later
        path.partials.scatter(
            s,
            scattered.pdf * go_on,
            reverse * go_on,
            scattered.wi.dot(n),
            scattered.delta,
            merges_here,
        );
        path.after_specular = scattered.delta;
        path.throughput *= scattered.weight / go_on;
        if path.throughput == Rgb::ZERO {
            return false;
        }
        path.ray = hit.surface.spawn_ray(scattered.wi);
        path.length += 1;
        path.length <= ctx.max_length
    }

    /// The paths `indices`: what they make, in path order. Eight at a time
    /// through the `LaneWorld` where given (and the CPU allows), the same bit
    /// for bit.
    fn trace(&self, lane_world: Option<&LaneWorld>, indices: Range<u64>) -> ChunkPaths {
        let mut out = ChunkPaths::default();
        // Which path made each vertex, splat and contribution: its place among `indices`
        let mut places = Vec::new();
        if self.ctx.keeps_vertices() {
            // Room for most chunks' vertices at once, not grown from nothing
            let expected = (indices.end - indices.start) as usize * EXPECTED_VERTICES;
            (out.vertices, places) = (Vec::with_capacity(expected), Vec::with_capacity(expected));
        }
        let mut rays = 0;
        let ray = |path: &Flight| {
            rays += 1;
            (path.ray, path.scope.held)
        };
        let bounce = |place, path: &mut Flight, hit: Option<&Hit>, drawn: Option<&Given>| {
            let Some(hit) = hit else { return false };
            let goes_on = self.bounce(place, path, hit, drawn, &mut out);
            places.resize(out.vertices.len(), place);
            if out.joins.waiting.len() >= JOINS {
                out.trace_joins(self.ctx);
            }
            goes_on
        };
        let count = (indices.end - indices.start) as usize;
        let (world, draws) = (self.ctx.world, LightDraws { ctx: self.ctx });
        flying::fly_drawing(lane_world, world, indices, |index| self.launch(index), ray, draws, bounce);
        out.counters.rays += rays;
        out.trace_joins(self.ctx);
        (out.vertices, out.ends) = reorder::by_item(&out.vertices, &places, count);
        out.splats = reorder::by_item(&out.splats, &out.joins.splat_places, count).0;
        out.contributions = reorder::by_item(&out.contributions, &out.joins.contribution_places, count).0;
        out
    }
}

/// A light vertex joined to the camera (t = 1), as the camera sees it
/// (`seen`; None: it does not): a splat on the pixel it lands on, weighed
/// against every other strategy for the same path (plain light tracing
/// weighs it 1: it is the only one it has), once its shadow ray, traced
/// with others (`ChunkPaths::trace_joins`), gets through.
fn join_camera(
    ctx: &Context,
    scope: &PathScope,
    vertex: &LightVertex,
    seen: Option<CameraConnection>,
    place: u32,
    out: &mut ChunkPaths,
) {
    let Some(seen) = seen else { return };
    let facing = vertex.facing();
    let f = vertex.bsdf.eval(vertex.wo, seen.to_camera, facing);
    if f == Rgb::ZERO {
        return;
    }
    let cos = seen.to_camera.dot(vertex.hit.normal).abs();
    let camera_pdf_a = seen.ray_pdf * cos / (seen.distance * seen.distance);
    let weight = if ctx.light_tracing {
        1.0
    } else {
        let reverse = vertex.bsdf.pdf(seen.to_camera, vertex.wo, facing) * vertex.bsdf.continuation();
        mis::to_camera(&ctx.strategies, &vertex.partials, camera_pdf_a, reverse, vertex.after_specular)
    };
    let value = vertex.throughput * f * (weight * camera_pdf_a / ctx.strategies.light_paths);
    let (shadow, t_max) = vertex.hit.spawn_ray_to(seen.lens, 0.0);
    let t_max = t_max - seen.start;
    out.counters.connections += 1;
    out.counters.rays += 1;
    if t_max <= 0.0 {
        return;
    }
    // Inside every wall at both ends, the segment cannot cross one
    let held = scope.held && ctx.world.holds(seen.lens - seen.to_camera * seen.start);
    let shadow = out.joins.shadows.push(Shadow::segment(shadow, t_max, held));
    let contribution = ctx.strategy_film.and_then(|film| {
        let pixel = film.pixel(seen.pixel.0, seen.pixel.1);
        let strategy = Strategy::Connect { length: vertex.length + 1, light_vertices: vertex.length + 1 };
        PixelTally::contribution(pixel, strategy, value, weight)
    });
    let splat = Splat { x: seen.pixel.0, y: seen.pixel.1, value };
    out.joins.waiting.push(Join { splat, contribution, shadow, place });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::bidir::mis::Strategies;
    use crate::render::integrators::bidir::strategies::StrategyFilm;
    use crate::render::integrators::photon_map::emit::LightPicker;
    use crate::render::settings::MisHeuristic;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::World;
    use crate::scene::{presets, Camera};

    /// Every preset, through a pinhole and a lens, and each way the light
    /// subpaths are used (light tracing, connecting, merging, both; the
    /// strategy view open or not; paths of two segments at most and of
    /// eight):
    /// eight at a time, their shadow rays eight at a time, the paths make
    /// what they make one at a time — the same vertices, ends, splats,
    /// contributions and counts, bit for bit.
    #[test]
    fn eight_at_a_time_make_what_one_at_a_time_make() {
        assert!(LaneWorld::runs_in_lanes(), "this CPU lacks AVX2: the lanes would be the scalar code here");
        let (width, height) = (48, 36);
        let film = StrategyFilm::new(width, height);
        // Each preset through its pinhole and through a lens, whose
        // samples light paths draw before they scatter
        let lenses = presets::names().flat_map(|name| [(name, 0.0), (name, 0.05)]);
        for (name, aperture_radius) in lenses {
            let scene = presets::preset(name).and_then(Result::ok).expect("preset");
            let camera = CameraModel::new(&Camera { aperture_radius, ..scene.camera.clone() }, width, height);
            assert_eq!(camera.has_lens(), aperture_radius > 0.0);
            let (world, visible_radius) = World::for_view(&scene, &camera, width, height);
            let lane_world = LaneWorld::new(&world).expect("a world the lanes trace");
            let picker = LightPicker::new(&world);
            let ways = [(false, false, true), (true, false, false), (false, true, false), (true, true, false)];
            let mut made = 0;
            // Paths cut short (at two segments: one vertex joined, none scattered) and not
            for (max_length, (connect, merge, light_tracing)) in ways.iter().flat_map(|&w| [(2, w), (8, w)]) {
                for strategy_film in [None, Some(&film)] {
                    let pixels = (width * height) as f32;
                    let lanes_ctx = Context {
                        world: &world,
                        lane_world: Some(&lane_world),
                        camera: &camera,
                        strategies: Strategies::new(MisHeuristic::Power, connect, merge, pixels, visible_radius * 0.01),
                        picker: &picker,
                        bounds: world.bounds(),
                        sky_bounds: world.bounds(),
                        background: world.lights.iter().position(|l| matches!(l, LightSource::Background { .. })),
                        max_length,
                        light_tracing,
                        strategy_film,
                    };
                    // One at a time with shadow rays one at a time too
                    let scalar_ctx = Context { lane_world: None, ..lanes_ctx };
                    // Not a multiple of eight, away from 0
                    let indices = 100..1123;
                    let one = Flights { ctx: &scalar_ctx, pass: 3, seed: 11 }.trace(None, indices.clone());
                    let eight = Flights { ctx: &lanes_ctx, pass: 3, seed: 11 }.trace(Some(&lane_world), indices);
                    let view = strategy_film.is_some();
                    let what = format!(
                        "{name}, lens {aperture_radius}, connect {connect}, merge {merge}, view {view}, {max_length} segments"
                    );
                    let vertex_bits = |paths: &ChunkPaths| format!("{:?}", paths.vertices);
                    assert!(vertex_bits(&one) == vertex_bits(&eight), "{what}: the vertices differ");
                    assert_eq!(one.ends, eight.ends, "{what}");
                    let splat_bits = |paths: &ChunkPaths| {
                        paths
                            .splats
                            .iter()
                            .map(|s| (s.x, s.y, s.value.to_array().map(f32::to_bits)))
                            .collect::<Vec<_>>()
                    };
                    assert!(splat_bits(&one) == splat_bits(&eight), "{what}: the splats differ");
                    assert_eq!(format!("{:?}", one.contributions), format!("{:?}", eight.contributions), "{what}");
                    assert_eq!(format!("{:?}", one.counters), format!("{:?}", eight.counters), "{what}");
                    made += eight.vertices.len() + eight.splats.len();
                    if strategy_film.is_some() && (connect || light_tracing) {
                        assert!(!eight.contributions.is_empty() || eight.splats.is_empty(), "{what}: no contributions");
                    }
                }
            }
            assert!(made > 1000, "{name}: only {made} vertices and splats made");
        }
    }
}
