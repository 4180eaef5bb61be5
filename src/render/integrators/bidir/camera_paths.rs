//! Camera subpaths: one per pixel each pass. At every non-specular vertex,
//! as the method asks: next-event estimation to a light, connections to
//! every vertex of the pixel's own light subpath, and merges with every
//! light vertex within the merge radius; where the path meets an emitter or
//! the background, their light. Each is weighed against every other
//! strategy that could have made the same path (`mis`).
//!
//! A tile's subpaths fly eight at a time (`flying`: their rays through the
//! paths' hit loop), and each keeps what it finds, in order, until it ends:
//! then its shadow rays are traced together, eight at a time, and what gets
//! through is added up in the order it was found. So the pixel is the sum
//! tracing each ray at once would make, bit for bit.

use std::cell::RefCell;

use glam::Vec3;

use super::light_paths::{LightPaths, LightVertex};
use super::merging::MergeGrid;
use super::mis::{self, MergeBehind, Partials};
use super::strategies::{Contribution, NoTally, PixelTally, Strategy, Tally};
use super::Context;
use crate::geometry::Ray;
use crate::render::integrators::flying::{self, DrawAtHits};
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::shadow_batch::ShadowBatch;
use crate::render::integrators::{reorder, Counters};
use crate::render::world::camera::CameraTile;
use crate::render::world::lane_world::{Given, PickedLight, Want};
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::occluders::Shadow;
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::uniform_sphere_pdf;
use crate::render::world::Hit;
use crate::scene::Rgb;

/// What the camera subpaths of a pass meet: the light subpaths and, for
/// merging, their vertices in a grid.
pub struct LightSide<'a> {
    pub paths: &'a LightPaths,
    pub grid: Option<&'a MergeGrid>,
    pub radius: f32,
}

/// A camera vertex, as the strategies at it read it.
struct CameraVertex<'a> {
    hit: &'a Hit,
    wo: Vec3,
    facing: Vec3,
    bsdf: &'a Bsdf,
    partials: &'a Partials,
    /// Segments from the camera.
    length: u32,
}

/// What a camera subpath found, in the order it found it, to add once its
/// shadow rays are traced.
#[derive(Default)]
struct Found {
    terms: Vec<Term>,
    shadows: Vec<Shadow>,
}

/// One strategy's part: `throughput · value` (weighed `weight`), nothing
/// if its shadow ray (an index into `Found::shadows`) is blocked. Told to
/// the strategy view as `tally` (a merge, merge by merge), added to the
/// pixel if `color` (a pixel's merges as their sum).
struct Term {
    tally: Option<Strategy>,
    color: bool,
    throughput: Rgb,
    value: Rgb,
    weight: f32,
    shadow: Option<u32>,
}

impl Found {
    /// A part that waits on its shadow ray (None: nothing, weighed 0).
    fn shadowed(&mut self, strategy: Strategy, throughput: Rgb, part: Option<(Rgb, f32, Shadow)>) {
        let (value, weight, shadow) = match part {
            Some((value, weight, shadow)) => {
                self.shadows.push(shadow);
                (value, weight, Some(self.shadows.len() as u32 - 1))
            }
            None => (Rgb::ZERO, 0.0, None),
        };
        self.terms.push(Term { tally: Some(strategy), color: true, throughput, value, weight, shadow });
    }

    /// A part that needs no shadow ray.
    fn seen(&mut self, tally: Option<Strategy>, color: bool, value: Rgb, weight: f32) {
        self.terms.push(Term { tally, color, throughput: Rgb::ONE, value, weight, shadow: None });
    }

    /// The parts that the shadow rays let through (`batch` has traced them
    /// from index `first` on), told to `tally` and added up in order.
    fn sum<T: Tally>(&mut self, batch: &ShadowBatch, first: u32, tally: &mut T) -> Rgb {
        let mut color = Rgb::ZERO;
        for term in &self.terms {
            let blocked = term.shadow.is_some_and(|i| batch.blocked(first + i));
            let (value, weight) = if blocked { (Rgb::ZERO, 0.0) } else { (term.value, term.weight) };
            let part = term.throughput * value;
            if let Some(strategy) = term.tally {
                tally.add(strategy, part, weight);
            }
            if term.color {
                color += part;
            }
        }
        self.terms.clear();
        color
    }
}

/// Paths that ended, waiting for their shadow rays, which are traced
/// together once there are `WAITING` of them (a few batches of eight) or
/// as many paths.
struct Ended {
    paths: Vec<EndedPath>,
    shadows: ShadowBatch,
}

/// A path that ended: its place in the tile, its small pixel, what it
/// found, and where its shadow rays start in `Ended::shadows`.
struct EndedPath {
    place: u32,
    small_pixel: u32,
    found: Found,
    first: u32,
}

const WAITING: usize = 32;

/// One camera subpath between its vertices.
struct CameraPath<'w> {
    /// Its pixel in the film, and (for the strategy view) its small pixel.
    pixel: usize,
    small_pixel: u32,
    sampler: Sampler,
    scope: PathScope<'w>,
    partials: Partials,
    /// A merge at the vertex it last left, counted if this one is specular.
    behind: MergeBehind,
    throughput: Rgb,
    ray: Ray,
    last_point: Vec3,
    specular_path: bool,
    /// Segments from the camera, `ray`'s included.
    length: u32,
    found: Found,
}

/// Camera subpaths draw their light samples and directions in the lanes
/// where they can: at every vertex that may go on.
struct CameraDraws<'c> {
    ctx: &'c Context<'c>,
}

impl DrawAtHits<CameraPath<'_>> for CameraDraws<'_> {
    fn want(&self, path: &CameraPath) -> Option<Want> {
        let ctx = self.ctx;
        let goes_on = !ctx.light_tracing && path.length < ctx.max_length;
        let light = ctx.strategies.connect;
        goes_on.then(|| Want { state: path.sampler.state(), light, join: false, scatter: true })
    }

    fn pick(&self, u: f32) -> Option<(usize, f32)> {
        self.ctx.picker.pick(u)
    }
}

/// The light of every camera sample of `tile` (of a film `width` wide),
/// into `out`; what each strategy brought, for the strategy view, into
/// `contributions` in the order of the samples.
pub fn trace(
    ctx: &Context,
    light: &LightSide,
    tile: &CameraTile,
    width: u32,
    counters: &mut Counters,
    out: &mut [Rgb],
    contributions: &mut Vec<Contribution>,
) {
    // What paths that ended leave for those that start
    let spare = RefCell::new(Vec::<Found>::new());
    let (start, count) = (contributions.len(), out.len());
    let mut places = Vec::new();
    let launch = |i: u64| {
        if ctx.max_length == 0 {
            return None;
        }
        let (x, y) = tile.rect.pixel(i as usize);
        let (ray, sampler) = tile.sample(i as usize);
        let scope = PathScope::new(ctx.world, ray.origin);
        Some(CameraPath {
            pixel: (y * width + x) as usize,
            small_pixel: ctx.strategy_film.map_or(0, |film| film.pixel(x, y)),
            sampler,
            scope,
            partials: Partials::camera(&ctx.strategies, ctx.camera.ray_pdf(ray.direction)),
            behind: MergeBehind::default(),
            throughput: Rgb::ONE,
            ray,
            last_point: ray.origin,
            specular_path: true,
            length: 1,
            found: spare.borrow_mut().pop().unwrap_or_default(),
        })
    };
    let mut rays = 0;
    let ray = |path: &CameraPath| {
        rays += 1;
        (path.ray, path.scope.held)
    };
    let mut ended = Ended { paths: Vec::new(), shadows: ShadowBatch::default() };
    // The ended paths' shadow rays traced, their light into `out`
    let mut finish = |ended: &mut Ended, contributions: &mut Vec<Contribution>| {
        ended.shadows.trace(ctx.lane_world, ctx.world);
        for EndedPath { place, small_pixel, mut found, first } in ended.paths.drain(..) {
            out[place as usize] = match ctx.strategy_film {
                Some(_) => found.sum(&ended.shadows, first, &mut PixelTally { pixel: small_pixel, out: contributions }),
                None => found.sum(&ended.shadows, first, &mut NoTally),
            };
            places.resize(contributions.len() - start, place);
            spare.borrow_mut().push(found);
        }
        ended.shadows.clear();
    };
    let bounce = |place: u32, path: &mut CameraPath, hit: Option<&Hit>, drawn: Option<&Given>| {
        if path.bounce(ctx, light, hit, drawn, counters) {
            return true;
        }
        let mut found = std::mem::take(&mut path.found);
        let first = ended.shadows.append(&mut found.shadows);
        ended.paths.push(EndedPath { place, small_pixel: path.small_pixel, found, first });
        if ended.shadows.count() as usize >= WAITING || ended.paths.len() >= WAITING {
            finish(&mut ended, contributions);
        }
        false
    };
    let draws = CameraDraws { ctx };
    flying::fly_drawing(ctx.lane_world, ctx.world, 0..count as u64, launch, ray, draws, bounce);
    finish(&mut ended, contributions);
    counters.rays += rays;
    if !places.is_empty() {
        let ordered = reorder::by_item(&contributions[start..], &places, count).0;
        contributions.truncate(start);
        contributions.extend(ordered);
    }
}

impl CameraPath<'_> {
    /// The path's vertex at `hit`, the nearest along its ray (None: it
    /// left the scene): what it finds there, then its next ray, from what
    /// it `drawn` there in the lanes if it did. False once the path ends.
    fn bounce(
        &mut self,
        ctx: &Context,
        light: &LightSide,
        hit: Option<&Hit>,
        drawn: Option<&Given>,
        counters: &mut Counters,
    ) -> bool {
        let (world, s) = (ctx.world, &ctx.strategies);
        let length = self.length;
        let throughput = self.throughput;
        let Some(hit) = hit else {
            let weight =
                background_weight(ctx, &self.partials, length, self.specular_path, self.last_point, self.ray.direction);
            let value = throughput * world.background * weight;
            self.found.seen(Some(Strategy::Connect { length, light_vertices: 0 }), true, value, weight);
            return false;
        };
        let (wo, n) = (-self.ray.direction, hit.surface.normal);
        // The camera's density is per solid angle at the lens, not at the
        // near clip the first ray starts from
        let distance =
            if length == 1 { hit.surface.t + ctx.camera.clip_distance(self.ray.direction) } else { hit.surface.t };
        self.partials.arrive(s, Some(distance * distance), wo.dot(n));
        self.behind.arrive(s, wo.dot(n));
        let emitted = world.emitted(hit, wo);
        if emitted != Rgb::ZERO {
            let weight = emitter_weight(ctx, &self.partials, length, self.specular_path, hit, wo, self.last_point);
            let value = throughput * emitted * weight;
            self.found.seen(Some(Strategy::Connect { length, light_vertices: 0 }), true, value, weight);
        }
        // Light tracing's camera paths only see what shines straight at them
        let bsdf = Bsdf::new(world.material_of(hit));
        if ctx.light_tracing || matches!(bsdf, Bsdf::Black) || length >= ctx.max_length {
            return false;
        }
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        let sampler = &mut self.sampler;
        if bsdf.is_specular() {
            // Light came to the vertex before through this one
            self.partials.merge_behind(s, self.behind);
        } else {
            let vertex = CameraVertex { hit, wo, facing, bsdf: &bsdf, partials: &self.partials, length };
            if s.connect {
                let picked = match drawn {
                    Some(given) => given.light,
                    None => draw_light(ctx, hit, sampler),
                };
                let part = direct(ctx, &self.scope, &vertex, picked, counters);
                let strategy = Strategy::Connect { length: length + 1, light_vertices: 1 };
                self.found.shadowed(strategy, throughput, part);
                for light_vertex in light.paths.path(self.pixel) {
                    if light_vertex.length + 1 + length > ctx.max_length {
                        break;
                    }
                    let part = connect(ctx, &self.scope, &vertex, light_vertex, counters);
                    let strategy = Strategy::Connect {
                        length: light_vertex.length + 1 + length,
                        light_vertices: light_vertex.length + 1,
                    };
                    self.found.shadowed(strategy, throughput, part);
                }
            }
            if s.merge {
                let sum = merge(ctx, light, &vertex, throughput, counters, &mut self.found);
                self.found.seen(None, true, sum, 0.0);
            }
        }
        let scattered = match drawn {
            Some(given) => given.resume(sampler),
            None => bsdf.sample(wo, n, sampler, Transport::Radiance),
        };
        let Some(scattered) = scattered else { return false };
        let go_on = bsdf.continuation();
        if sampler.next_f32() >= go_on {
            return false;
        }
        let reverse = if scattered.delta { scattered.pdf } else { bsdf.pdf(scattered.wi, wo, facing) };
        // Whether a merge here is a strategy can hang on the next vertex
        let merges_here = s.merges_at(false);
        self.behind = self.partials.scatter(
            s,
            scattered.pdf * go_on,
            reverse * go_on,
            scattered.wi.dot(n),
            scattered.delta,
            merges_here,
        );
        self.throughput *= scattered.weight / go_on;
        self.specular_path &= scattered.delta;
        if self.throughput == Rgb::ZERO {
            return false;
        }
        self.last_point = hit.surface.point;
        self.ray = hit.surface.spawn_ray(scattered.wi);
        self.length += 1;
        true
    }
}

/// The weight of an emitter met by a camera subpath of `length` segments,
/// from `last_point`: 1 seen straight from the camera (no other strategy
/// reaches a pinhole), or where no light sampling or emission could have
/// made the path (an emissive plane); with merging alone, only down a
/// chain of mirrors and glass (merges make every other such path).
fn emitter_weight(
    ctx: &Context,
    partials: &Partials,
    length: u32,
    specular_path: bool,
    hit: &Hit,
    wo: Vec3,
    last_point: Vec3,
) -> f32 {
    if length == 1 {
        return 1.0;
    }
    if !ctx.strategies.connect {
        return if specular_path { 1.0 } else { 0.0 };
    }
    let Some(index) = ctx.world.objects[hit.object as usize].light else { return 1.0 };
    let light = &ctx.world.lights[index as usize];
    let pick = ctx.picker.probability(index as usize);
    let (point, normal) = (hit.surface.point, hit.surface.normal);
    let direct = pick * light.direct_pdf_a(last_point, point, normal);
    let emission = pick * light.emission_pdf(ctx.bounds_of(light), point, normal, wo);
    mis::hit_light(&ctx.strategies, partials, direct, emission)
}

/// The weight of the background met by a camera subpath leaving
/// `last_point` along `direction` (before `arrive`: it is met at no
/// distance).
fn background_weight(
    ctx: &Context,
    partials: &Partials,
    length: u32,
    specular_path: bool,
    last_point: Vec3,
    direction: Vec3,
) -> f32 {
    if length == 1 {
        return 1.0;
    }
    if !ctx.strategies.connect {
        return if specular_path { 1.0 } else { 0.0 };
    }
    let Some(index) = ctx.background else { return 1.0 };
    let pick = ctx.picker.probability(index);
    let light = &ctx.world.lights[index];
    let direct = pick * uniform_sphere_pdf();
    let emission = pick * light.emission_pdf(ctx.bounds_of(light), last_point, Vec3::ZERO, -direction);
    mis::hit_light(&ctx.strategies, partials, direct, emission)
}

/// A light chosen by power for next-event estimation at `hit`, and a
/// sample of it: as `LaneWorld::draw_at_hits` draws it in the lanes.
fn draw_light(ctx: &Context, hit: &Hit, sampler: &mut Sampler) -> Option<PickedLight> {
    let (index, pick) = ctx.picker.pick(sampler.next_f32())?;
    Some((index, pick, ctx.world.lights[index].sample(&hit.surface, sampler.next_2d())))
}

/// Next-event estimation (s = 1) from the light `picked` and its sample:
/// its contribution and MIS weight, and the shadow ray that decides them.
fn direct(
    ctx: &Context,
    scope: &PathScope,
    vertex: &CameraVertex,
    picked: Option<PickedLight>,
    counters: &mut Counters,
) -> Option<(Rgb, f32, Shadow)> {
    let (index, pick, sample) = picked?;
    let light = &ctx.world.lights[index];
    let (wo, facing, bsdf) = (vertex.wo, vertex.facing, vertex.bsdf);
    counters.connections += 1;
    let sample = sample?;
    let (f, pdf) = bsdf.eval_pdf(wo, sample.wi, facing);
    if f == Rgb::ZERO {
        return None;
    }
    counters.rays += 1;
    let point = vertex.hit.surface.point;
    let (direct_pdf, cos_at_light) = light.direct_density(&sample, point);
    // Infinite lights emit toward the lit point from their disc
    let from = if light.is_finite() { sample.point } else { point };
    let emission_pdf = light.emission_pdf(ctx.bounds_of(light), from, sample.normal, -sample.wi);
    let go_on = bsdf.continuation();
    let bsdf_pdf = if light.is_delta() { 0.0 } else { pdf * go_on };
    let reverse = bsdf.pdf(sample.wi, wo, facing) * go_on;
    let cos = sample.wi.dot(facing);
    let (s, partials) = (&ctx.strategies, vertex.partials);
    let weight = mis::direct(s, partials, bsdf_pdf, reverse, pick, direct_pdf, emission_pdf, cos, cos_at_light);
    Some((f * sample.value * (cos * weight / pick), weight, Shadow::toward(&sample, scope.held)))
}

/// A camera vertex connected to a vertex of the pixel's light subpath:
/// its contribution and MIS weight, and the shadow ray that decides them.
fn connect(
    ctx: &Context,
    scope: &PathScope,
    vertex: &CameraVertex,
    light: &LightVertex,
    counters: &mut Counters,
) -> Option<(Rgb, f32, Shadow)> {
    let to_light = light.hit.point - vertex.hit.surface.point;
    let distance2 = to_light.length_squared();
    let direction = to_light / distance2.sqrt();
    let (wo, facing, bsdf) = (vertex.wo, vertex.facing, vertex.bsdf);
    let (camera_f, camera_pdf) = bsdf.eval_pdf(wo, direction, facing);
    if camera_f == Rgb::ZERO {
        return None;
    }
    let light_facing = light.facing();
    let (light_f, light_pdf) = light.bsdf.eval_pdf(light.wo, -direction, light_facing);
    if light_f == Rgb::ZERO {
        return None;
    }
    let (cos_camera, cos_light) = (direction.dot(facing), -direction.dot(light_facing));
    let (camera_go_on, light_go_on) = (bsdf.continuation(), light.bsdf.continuation());
    let camera_pdf_a = camera_pdf * camera_go_on * cos_light / distance2;
    let camera_reverse = bsdf.pdf(direction, wo, facing) * camera_go_on;
    let light_pdf_a = light_pdf * light_go_on * cos_camera / distance2;
    let light_reverse = light.bsdf.pdf(-direction, light.wo, light_facing) * light_go_on;
    let s = &ctx.strategies;
    let weight = mis::connect(
        s,
        &light.partials,
        vertex.partials,
        camera_pdf_a,
        light_pdf_a,
        light_reverse,
        camera_reverse,
        light.after_specular,
    );
    let contribution = light.throughput * camera_f * light_f * (weight * cos_camera * cos_light / distance2);
    counters.connections += 1;
    counters.rays += 1;
    if contribution == Rgb::ZERO {
        return None;
    }
    let (shadow, t_max) = vertex.hit.surface.spawn_ray_to(light.hit.point, light.hit.error);
    Some((contribution, weight, Shadow::segment(shadow, t_max, scope.held && light.held)))
}

/// Every light vertex within the merge radius, merged into the camera
/// vertex: the light it brings (times `throughput`), as a density estimate
/// on the radius's disc; each merge kept for the strategy view, if open.
fn merge(
    ctx: &Context,
    light: &LightSide,
    vertex: &CameraVertex,
    throughput: Rgb,
    counters: &mut Counters,
    found: &mut Found,
) -> Rgb {
    // Caustic merges only in a scene with no caustic path: no query
    let Some(grid) = light.grid.filter(|grid| !grid.is_empty()) else { return Rgb::ZERO };
    let normalization = ctx.strategies.vm_normalization;
    let (wo, facing, bsdf) = (vertex.wo, vertex.facing, vertex.bsdf);
    let go_on = bsdf.continuation();
    let mut sum = Rgb::ZERO;
    grid.for_each_within(vertex.hit.surface.point, light.radius, |light_vertex| {
        if light_vertex.length + vertex.length > ctx.max_length {
            return;
        }
        let (f, pdf) = bsdf.eval_pdf(wo, light_vertex.wo, facing);
        if f == Rgb::ZERO {
            return;
        }
        let camera_pdf = pdf * go_on;
        // The way back is the light vertex's to continue
        let camera_reverse = bsdf.pdf(light_vertex.wo, wo, facing) * light_vertex.continuation;
        let s = &ctx.strategies;
        let weight = mis::merge(s, &light_vertex.partials, vertex.partials, camera_pdf, camera_reverse);
        let value = light_vertex.throughput * f * weight;
        if ctx.strategy_film.is_some() {
            let strategy =
                Strategy::Merge { length: light_vertex.length + vertex.length, camera_vertex: vertex.length };
            found.seen(Some(strategy), false, throughput * value * normalization, weight);
        }
        sum += value;
        counters.merges += 1;
    });
    throughput * sum * normalization
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::bidir::light_paths;
    use crate::render::integrators::bidir::mis::Strategies;
    use crate::render::integrators::bidir::strategies::StrategyFilm;
    use crate::render::integrators::photon_map::emit::LightPicker;
    use crate::render::settings::MisHeuristic;
    use crate::render::world::camera::{CameraModel, TileRect};
    use crate::render::world::lane_world::LaneWorld;
    use crate::render::world::light::LightSource;
    use crate::render::world::rng::PassStreams;
    use crate::render::world::World;
    use crate::scene::presets;

    /// Every preset, connecting and merging (VCM, merges everywhere or on
    /// caustic paths only), the strategy view open or not: the camera
    /// subpaths of a tile flown eight at a time, their shadow rays traced in
    /// lanes, make what one at a time with every shadow ray alone makes —
    /// the same pixels, contributions and counts, bit for bit.
    #[test]
    fn eight_at_a_time_make_what_one_at_a_time_make() {
        assert!(LaneWorld::runs_in_lanes(), "this CPU lacks AVX2: the lanes would be the scalar code here");
        let (width, height) = (40, 30);
        let film = StrategyFilm::new(width, height);
        for name in presets::names() {
            let scene = presets::preset(name).and_then(Result::ok).expect("preset");
            let camera = CameraModel::new(&scene.camera, width, height);
            let (world, visible_radius) = World::for_view(&scene, &camera, width, height);
            let lane_world = LaneWorld::new(&world).expect("a world the lanes trace");
            let picker = LightPicker::new(&world);
            let pixels = (width * height) as f32;
            let radius = visible_radius * 0.01;
            for (strategy_film, caustics) in [(None, false), (Some(&film), false), (None, true)] {
                let lanes_ctx = Context {
                    world: &world,
                    lane_world: Some(&lane_world),
                    camera: &camera,
                    strategies: Strategies::with_merges(MisHeuristic::Power, true, true, caustics, pixels, radius),
                    picker: &picker,
                    bounds: world.bounds(),
                    sky_bounds: world.bounds(),
                    background: world.lights.iter().position(|l| matches!(l, LightSource::Background { .. })),
                    max_length: 8,
                    light_tracing: false,
                    strategy_film,
                };
                let scalar_ctx = Context { lane_world: None, ..lanes_ctx };
                let paths = light_paths::trace(&lanes_ctx, pixels as u64, 2, 5, &|| true).expect("not cancelled");
                let grid = MergeGrid::build(&paths, radius, &lanes_ctx.strategies, Default::default());
                let light = LightSide { paths: &paths, grid: Some(&grid), radius };
                // A tile that does not split into eights, away from the corner
                let rect = TileRect { x: 3, y: 5, width: 29, height: 11 };
                let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(2, 5) };
                let run = |ctx: &Context| {
                    let (mut counters, mut values, mut contributions) =
                        (Counters::default(), vec![Rgb::splat(-1.0); rect.pixels()], Vec::new());
                    trace(ctx, &light, &tile, width, &mut counters, &mut values, &mut contributions);
                    let bits: Vec<[u32; 3]> = values.iter().map(|v| v.to_array().map(f32::to_bits)).collect();
                    (bits, format!("{contributions:?}"), format!("{counters:?}"))
                };
                let (eight, one) = (run(&lanes_ctx), run(&scalar_ctx));
                let view = strategy_film.is_some();
                assert!(eight.0 == one.0, "{name}, view {view}, caustics {caustics}: the pixels differ");
                assert_eq!(eight.1, one.1, "{name}, view {view}, caustics {caustics}: the contributions differ");
                assert_eq!(eight.2, one.2, "{name}, view {view}, caustics {caustics}");
                let lit = eight.0.iter().filter(|v| v.iter().any(|&c| c != 0)).count();
                assert!(lit > rect.pixels() / 4, "{name}: only {lit} pixels lit");
                if view {
                    assert!(eight.1.len() > 100, "{name}: no contributions");
                }
            }
        }
    }
}
