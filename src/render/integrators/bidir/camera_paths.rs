//! Camera subpaths: one per pixel each pass. At every non-specular vertex,
//! as the method asks: next-event estimation to a light, connections to
//! every vertex of the pixel's own light subpath, and merges with every
//! light vertex within the merge radius; where the path meets an emitter or
//! the background, their light. Each is weighed against every other
//! strategy that could have made the same path (`mis`).

use glam::Vec3;

use super::light_paths::{LightPaths, LightVertex};
use super::merging::MergeGrid;
use super::mis::{self, Partials};
use super::strategies::{Strategy, Tally};
use super::Context;
use crate::geometry::Ray;
use crate::render::integrators::next_event::PathScope;
use crate::render::integrators::Counters;
use crate::render::world::bsdf::{Bsdf, Transport};
use crate::render::world::light::{LightSample, LightSource};
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

/// The light of pixel `pixel`'s camera subpath starting along `ray`, each
/// strategy's part also told to `tally`.
pub fn radiance<T: Tally>(
    ctx: &Context,
    light: &LightSide,
    pixel: usize,
    ray: Ray,
    sampler: &mut Sampler,
    counters: &mut Counters,
    tally: &mut T,
) -> Rgb {
    let (world, s) = (ctx.world, &ctx.strategies);
    let scope = PathScope::new(world, ray.origin);
    let mut partials = Partials::camera(s, ctx.camera.ray_pdf(ray.direction));
    let (mut throughput, mut color) = (Rgb::ONE, Rgb::ZERO);
    let (mut ray, mut last_point, mut specular_path) = (ray, ray.origin, true);
    for length in 1..ctx.max_length + 1 {
        counters.rays += 1;
        let Some(hit) = scope.intersect(&ray) else {
            let weight = background_weight(ctx, &partials, length, specular_path, last_point, ray.direction);
            let value = throughput * world.background * weight;
            tally.add(Strategy::Connect { length, light_vertices: 0 }, value, weight);
            color += value;
            break;
        };
        let (wo, n) = (-ray.direction, hit.surface.normal);
        // The camera's density is per solid angle at the lens, not at the
        // near clip the first ray starts from
        let distance =
            if length == 1 { hit.surface.t + ctx.camera.clip_distance(ray.direction) } else { hit.surface.t };
        partials.arrive(s, Some(distance * distance), wo.dot(n));
        let emitted = world.emitted(&hit, wo);
        if emitted != Rgb::ZERO {
            let weight = emitter_weight(ctx, &partials, length, specular_path, &hit, wo, last_point);
            let value = throughput * emitted * weight;
            tally.add(Strategy::Connect { length, light_vertices: 0 }, value, weight);
            color += value;
        }
        // Light tracing's camera paths only see what shines straight at them
        let bsdf = Bsdf::new(world.material_of(&hit));
        if ctx.light_tracing || matches!(bsdf, Bsdf::Black) || length >= ctx.max_length {
            break;
        }
        let facing = if wo.dot(n) < 0.0 { -n } else { n };
        if !bsdf.is_specular() {
            let vertex = CameraVertex { hit: &hit, wo, facing, bsdf: &bsdf, partials: &partials, length };
            if s.connect {
                let (value, weight) = direct(ctx, &scope, &vertex, sampler, counters);
                tally.add(Strategy::Connect { length: length + 1, light_vertices: 1 }, throughput * value, weight);
                color += throughput * value;
                for light_vertex in light.paths.path(pixel) {
                    if light_vertex.length + 1 + length > ctx.max_length {
                        break;
                    }
                    let (value, weight) = connect(ctx, &scope, &vertex, light_vertex, counters);
                    let strategy = Strategy::Connect {
                        length: light_vertex.length + 1 + length,
                        light_vertices: light_vertex.length + 1,
                    };
                    tally.add(strategy, throughput * value, weight);
                    color += throughput * value;
                }
            }
            if s.merge {
                color += merge(ctx, light, &vertex, throughput, counters, tally);
            }
        }
        let Some(scattered) = bsdf.sample(wo, n, sampler, Transport::Radiance) else { break };
        let go_on = bsdf.continuation();
        if sampler.next_f32() >= go_on {
            break;
        }
        let reverse = if scattered.delta { scattered.pdf } else { bsdf.pdf(scattered.wi, wo, facing) };
        partials.scatter(s, scattered.pdf * go_on, reverse * go_on, scattered.wi.dot(n), scattered.delta);
        throughput *= scattered.weight / go_on;
        specular_path &= scattered.delta;
        if throughput == Rgb::ZERO {
            break;
        }
        last_point = hit.surface.point;
        ray = hit.surface.spawn_ray(scattered.wi);
    }
    color
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
    let emission = pick * light.emission_pdf(ctx.bounds, point, normal, wo);
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
    let emission = pick * light.emission_pdf(ctx.bounds, last_point, Vec3::ZERO, -direction);
    mis::hit_light(&ctx.strategies, partials, direct, emission)
}

/// Next-event estimation (s = 1): a light chosen by power, a sample of it;
/// its contribution and MIS weight.
fn direct(
    ctx: &Context,
    scope: &PathScope,
    vertex: &CameraVertex,
    sampler: &mut Sampler,
    counters: &mut Counters,
) -> (Rgb, f32) {
    let none = (Rgb::ZERO, 0.0);
    let Some((index, pick)) = ctx.picker.pick(sampler.next_f32()) else { return none };
    let light = &ctx.world.lights[index];
    let (wo, facing, bsdf) = (vertex.wo, vertex.facing, vertex.bsdf);
    let shade = |sample: &LightSample| Some(bsdf.eval_pdf(wo, sample.wi, facing)).filter(|(f, _)| *f != Rgb::ZERO);
    counters.connections += 1;
    let Some((sample, (f, pdf))) = scope.light_sample(light, vertex.hit, sampler.next_2d(), counters, shade) else {
        return none;
    };
    let point = vertex.hit.surface.point;
    let (direct_pdf, cos_at_light) = match light {
        LightSource::Point { .. } | LightSource::Spot { .. } => ((sample.point - point).length_squared(), 1.0),
        LightSource::Directional { .. } => (1.0, 1.0),
        LightSource::Background { .. } => (sample.pdf, 1.0),
        LightSource::Area { .. } => (sample.pdf, sample.normal.dot(-sample.wi)),
    };
    // Infinite lights emit toward the lit point from their disc
    let from = if light.is_finite() { sample.point } else { point };
    let emission_pdf = light.emission_pdf(ctx.bounds, from, sample.normal, -sample.wi);
    let go_on = bsdf.continuation();
    let bsdf_pdf = if light.is_delta() { 0.0 } else { pdf * go_on };
    let reverse = bsdf.pdf(sample.wi, wo, facing) * go_on;
    let cos = sample.wi.dot(facing);
    let (s, partials) = (&ctx.strategies, vertex.partials);
    let weight = mis::direct(s, partials, bsdf_pdf, reverse, pick, direct_pdf, emission_pdf, cos, cos_at_light);
    (f * sample.value * (cos * weight / pick), weight)
}

/// A camera vertex connected to a vertex of the pixel's light subpath:
/// its contribution and MIS weight.
fn connect(
    ctx: &Context,
    scope: &PathScope,
    vertex: &CameraVertex,
    light: &LightVertex,
    counters: &mut Counters,
) -> (Rgb, f32) {
    let none = (Rgb::ZERO, 0.0);
    let to_light = light.hit.point - vertex.hit.surface.point;
    let distance2 = to_light.length_squared();
    let direction = to_light / distance2.sqrt();
    let (wo, facing, bsdf) = (vertex.wo, vertex.facing, vertex.bsdf);
    let (camera_f, camera_pdf) = bsdf.eval_pdf(wo, direction, facing);
    if camera_f == Rgb::ZERO {
        return none;
    }
    let light_facing = light.facing();
    let (light_f, light_pdf) = light.bsdf.eval_pdf(light.wo, -direction, light_facing);
    if light_f == Rgb::ZERO {
        return none;
    }
    let (cos_camera, cos_light) = (direction.dot(facing), -direction.dot(light_facing));
    let (camera_go_on, light_go_on) = (bsdf.continuation(), light.bsdf.continuation());
    let camera_pdf_a = camera_pdf * camera_go_on * cos_light / distance2;
    let camera_reverse = bsdf.pdf(direction, wo, facing) * camera_go_on;
    let light_pdf_a = light_pdf * light_go_on * cos_camera / distance2;
    let light_reverse = light.bsdf.pdf(-direction, light.wo, light_facing) * light_go_on;
    let s = &ctx.strategies;
    let weight =
        mis::connect(s, &light.partials, vertex.partials, camera_pdf_a, light_pdf_a, light_reverse, camera_reverse);
    let contribution = light.throughput * camera_f * light_f * (weight * cos_camera * cos_light / distance2);
    counters.connections += 1;
    counters.rays += 1;
    let (shadow, t_max) = vertex.hit.surface.spawn_ray_to(light.hit.point, light.hit.error);
    if contribution == Rgb::ZERO || ctx.blocked(scope.held && light.held, &shadow, t_max) {
        return none;
    }
    (contribution, weight)
}

/// Every light vertex within the merge radius, merged into the camera
/// vertex: the light it brings (times `throughput`), as a density estimate
/// on the radius's disc.
fn merge<T: Tally>(
    ctx: &Context,
    light: &LightSide,
    vertex: &CameraVertex,
    throughput: Rgb,
    counters: &mut Counters,
    tally: &mut T,
) -> Rgb {
    let Some(grid) = light.grid else { return Rgb::ZERO };
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
        let strategy = Strategy::Merge { length: light_vertex.length + vertex.length, camera_vertex: vertex.length };
        tally.add(strategy, throughput * value * normalization, weight);
        sum += value;
        counters.merges += 1;
    });
    throughput * sum * normalization
}
