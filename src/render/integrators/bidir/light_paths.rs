//! Light subpaths: one per pixel each pass, from a light chosen in
//! proportion to its power, bouncing by the surfaces' BSDFs with Russian
//! roulette. Each non-specular vertex is kept (for connections and merges)
//! and, where connecting is on, joined to the camera: a splat on the pixel
//! it lands on. Path i's random stream is fixed by (i, pass, seed), and
//! chunks are joined in order, so nothing depends on the thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::mis::{self, Partials};
use super::strategies::{Contribution, PixelTally, Strategy, Tally};
use super::Context;
use crate::geometry::SurfaceHit;
use crate::render::film::Splat;
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::Counters;
use crate::render::world::bsdf::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
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
    pub vertices: Vec<LightVertex>,
    /// Where each path's vertices end in `vertices` (they start where the
    /// previous path's end).
    pub ends: Vec<u32>,
    /// Joins to the camera, by chunk in the order of the paths.
    pub splats: Vec<Vec<Splat>>,
    /// The same, by strategy, where the strategy view asked for them.
    pub contributions: Vec<Vec<Contribution>>,
    pub counters: Counters,
}

impl LightPaths {
    /// The vertices of path `index`.
    #[inline]
    pub fn path(&self, index: usize) -> &[LightVertex] {
        let start = if index == 0 { 0 } else { self.ends[index - 1] as usize };
        &self.vertices[start..self.ends[index] as usize]
    }
}

/// Trace `count` light subpaths of pass `pass`, asking `keep_going` before
/// each chunk: None once it says no.
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
            let mut out = ChunkPaths::default();
            for index in chunk as u64 * CHUNK..((chunk as u64 + 1) * CHUNK).min(count) {
                let mut sampler = Sampler::new(index, pass, seed ^ LIGHT_SALT);
                trace_one(ctx, &mut sampler, &mut out);
                out.ends.push(out.vertices.len() as u32);
            }
            Some(out)
        })
        .collect();
    let mut paths = LightPaths {
        vertices: Vec::new(),
        ends: Vec::new(),
        splats: Vec::new(),
        contributions: Vec::new(),
        counters: Counters::default(),
    };
    for chunk in per_chunk? {
        let offset = paths.vertices.len() as u32;
        paths.ends.extend(chunk.ends.iter().map(|end| end + offset));
        paths.vertices.extend(chunk.vertices);
        paths.splats.push(chunk.splats);
        paths.contributions.push(chunk.contributions);
        paths.counters.add(&chunk.counters);
    }
    paths.counters.light_vertices = paths.vertices.len() as u64;
    Some(paths)
}

#[derive(Default)]
struct ChunkPaths {
    vertices: Vec<LightVertex>,
    ends: Vec<u32>,
    splats: Vec<Splat>,
    contributions: Vec<Contribution>,
    counters: Counters,
}

fn trace_one(ctx: &Context, sampler: &mut Sampler, out: &mut ChunkPaths) {
    let (world, s) = (ctx.world, &ctx.strategies);
    let Some((index, pick)) = ctx.picker.pick(sampler.next_f32()) else { return };
    let light = &world.lights[index];
    let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
    let emission = light.emit(ctx.bounds, u1, u2);
    if !(emission.pdf > 0.0 && emission.power.is_finite()) {
        return;
    }
    let mut throughput = emission.power / pick;
    let mut partials = Partials::light(s, emission.pdf * pick, emission.cos, light.is_delta());
    let scope = PathScope::new(world, emission.ray.origin);
    let mut ray = emission.ray;
    for length in 1..ctx.max_length + 1 {
        out.counters.rays += 1;
        let Some(hit) = scope.intersect(&ray) else { return };
        let (wo, n) = (-ray.direction, hit.surface.normal);
        if length == 1 {
            let direct = light.direct_pdf_a(hit.surface.point, emission.point, emission.normal);
            partials.first_hit(s, direct * pick);
        }
        let from_infinity = length == 1 && !light.is_finite();
        let distance2 = hit.surface.t * hit.surface.t;
        partials.arrive(s, (!from_infinity).then_some(distance2), wo.dot(n));
        let bsdf = Bsdf::new(world.material_of(&hit));
        if !bsdf.is_specular() {
            let vertex = LightVertex { hit: hit.surface, wo, bsdf, throughput, length, partials, held: scope.held };
            if ctx.keeps_vertices() {
                out.vertices.push(vertex);
            }
            if s.connect || ctx.light_tracing {
                join_camera(ctx, &scope, &vertex, sampler, out);
            }
        }
        // A longer path would have no strategy left to finish it
        if length + 2 > ctx.max_length {
            return;
        }
        let Some(scattered) = bsdf.sample(wo, n, sampler, Transport::Importance) else { return };
        let go_on = bsdf.continuation();
        if sampler.next_f32() >= go_on {
            return;
        }
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let reverse = if scattered.delta { scattered.pdf } else { bsdf.pdf(scattered.wi, wo, facing) };
        partials.scatter(s, scattered.pdf * go_on, reverse * go_on, scattered.wi.dot(n), scattered.delta);
        throughput *= scattered.weight / go_on;
        if throughput == Rgb::ZERO {
            return;
        }
        ray = hit.surface.spawn_ray(scattered.wi);
    }
}

/// A light vertex joined to the camera (t = 1): a splat on the pixel it
/// lands on, weighed against every other strategy for the same path
/// (plain light tracing weighs it 1: it is the only one it has).
fn join_camera(ctx: &Context, scope: &PathScope, vertex: &LightVertex, sampler: &mut Sampler, out: &mut ChunkPaths) {
    let lens = if ctx.camera.has_lens() { sampler.next_2d() } else { glam::Vec2::ZERO };
    let Some(seen) = ctx.camera.connect(vertex.hit.point, lens) else { return };
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
        mis::to_camera(&ctx.strategies, &vertex.partials, camera_pdf_a, reverse)
    };
    let value = vertex.throughput * f * (weight * camera_pdf_a / ctx.strategies.light_paths);
    let (shadow, t_max) = vertex.hit.spawn_ray_to(seen.lens, 0.0);
    let t_max = t_max - seen.start;
    out.counters.connections += 1;
    out.counters.rays += 1;
    // Inside every wall at both ends, the segment cannot cross one
    let held = scope.held && ctx.world.holds(seen.lens - seen.to_camera * seen.start);
    if t_max <= 0.0 || ctx.blocked(held, &shadow, t_max) {
        return;
    }
    out.splats.push(Splat { x: seen.pixel.0, y: seen.pixel.1, value });
    if let Some(film) = ctx.strategy_film {
        let pixel = film.pixel(seen.pixel.0, seen.pixel.1);
        let strategy = Strategy::Connect { length: vertex.length + 1, light_vertices: vertex.length + 1 };
        PixelTally { pixel, out: &mut out.contributions }.add(strategy, value, weight);
    }
}
