//! Path tracing: physically based BSDFs, next-event estimation toward one
//! light per bounce, multiple importance sampling between light and BSDF
//! sampling for area lights, Russian roulette.

use super::next_event::PathScope;
use super::{path_lanes, Stage};
use super::{Counters, ROULETTE_DEPTH};
use crate::faults::{self, Fault};
use crate::geometry::Ray;
use crate::render::world::camera::CameraTile;
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::{power_heuristic, uniform_sphere_pdf};
use crate::render::world::World;
use crate::scene::Rgb;

/// Path tracing: eight paths at a time where the lanes can trace the world
/// (`Stage::lanes`; the same samples bit for bit), one at a time elsewhere.
pub struct PathTracer {
    max_depth: u32,
}

impl PathTracer {
    pub fn new(max_depth: u32) -> Self {
        Self { max_depth }
    }

    #[inline]
    pub fn radiance(&self, world: &World, ray: &Ray, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
        radiance(world, ray, self.max_depth, sampler, counters)
    }

    /// One sample of every pixel of `tile`, each handed to `out` with its
    /// index as it is done (`LaneWorld::radiance`).
    pub fn render_tile(
        &self,
        stage: &Stage,
        tile: &CameraTile,
        out: &mut impl FnMut(usize, Rgb),
        counters: &mut Counters,
    ) {
        if let Some(lanes) = stage.lanes {
            return path_lanes::radiance(lanes, stage.world, tile, self.max_depth, out, counters);
        }
        for i in 0..tile.len() {
            let (ray, mut sampler) = tile.sample(i);
            out(i, self.radiance(stage.world, &ray, &mut sampler, counters));
        }
    }
}

/// Radiance along `ray` carried by paths of at most `max_depth` segments
/// (`RenderSettings::max_depth`): at the last segment's end only what it
/// sees glowing counts, both ways of finding a path of that length (light
/// sampling and the BSDF's) held to the same cap.
pub fn radiance(world: &World, ray: &Ray, max_depth: u32, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
    let scope = PathScope::new(world, ray.origin);
    let mut ray = *ray;
    let mut radiance = Rgb::ZERO;
    let mut throughput = Rgb::ONE;
    // Emission found by a delta bounce (or the camera) was not light-sampled
    let mut after_delta = true;
    let mut last_pdf = 0.0;
    let mut last_point = ray.origin;
    let light_count = world.lights.len();
    let pick_pdf = 1.0 / light_count.max(1) as f32;

    for depth in 0..max_depth {
        counters.rays += 1;
        let Some(hit) = scope.intersect(&ray) else {
            // The background, weighted against sampling it as a light
            let weight = if after_delta { 1.0 } else { power_heuristic(last_pdf, pick_pdf * uniform_sphere_pdf()) };
            radiance += throughput * world.background * weight;
            break;
        };
        let wo = -ray.direction;

        // Emission reached by this ray, weighted against light sampling
        let emitted = world.emitted(&hit, wo);
        if emitted != Rgb::ZERO {
            let weight = match world.objects[hit.object as usize].light {
                Some(light) if !after_delta => {
                    power_heuristic(last_pdf, pick_pdf * world.lights[light as usize].pdf(last_point, &hit.surface))
                }
                _ => 1.0,
            };
            radiance += throughput * emitted * weight;
        }
        if depth + 1 == max_depth {
            break;
        }

        let bsdf = Bsdf::new(world.material_of(&hit));
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };

        // Next-event estimation: one light, chosen uniformly
        if !bsdf.is_specular() {
            radiance += scope.one_light(&hit, wo, facing, &bsdf, throughput, sampler, counters);
        }

        let Some(scattered) = bsdf.sample(wo, n, sampler, Transport::Radiance) else {
            break;
        };
        throughput *= scattered.weight;
        after_delta = scattered.delta;
        last_pdf = scattered.pdf;
        last_point = hit.surface.point;

        // A path that can carry no more light (off a black surface) ends
        // now, not at the roulette: the bounces after it would add nothing
        let survive = throughput.max_element().min(0.95);
        if survive <= 0.0 {
            break;
        }
        if depth + 1 >= ROULETTE_DEPTH {
            if sampler.next_f32() >= survive {
                break;
            }
            if !faults::active(Fault::RouletteUndivided) {
                throughput /= survive;
            }
        }
        ray = hit.surface.spawn_ray(scattered.wi);
    }
    radiance
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::settings::RenderSettings;
    use crate::render::world::camera::{CameraModel, TileRect};
    use crate::render::world::lane_world::LaneWorld;
    use crate::render::world::rng::PassStreams;

    /// A tile rendered through the lanes and one at a time (what a CPU
    /// without AVX2 renders): the same samples bit for bit, each handed out
    /// once (`tests/path_lanes.rs` holds the lanes to the scalar tracer at
    /// length).
    #[test]
    fn a_tile_in_lanes_is_the_tile_one_at_a_time() {
        let scene = crate::scene::presets::preset("smallpt").and_then(Result::ok).expect("smallpt preset");
        let camera = CameraModel::new(&scene.camera, 24, 18);
        let (world, _) = World::for_view(&scene, &camera, 24, 18);
        let rect = TileRect { x: 0, y: 0, width: 24, height: 18 };
        let tile = CameraTile { camera: &camera, rect, streams: PassStreams::new(0, 3) };
        let lanes = LaneWorld::new(&world).expect("spheres only, on a CPU with AVX2");
        let settings = RenderSettings::default();
        let tracer = PathTracer::new(32);
        let mut rendered = Vec::new();
        for lanes in [Some(&lanes), None] {
            let stage = Stage { world: &world, camera: &camera, settings: &settings, lanes };
            let (mut got, mut handed_out, mut counters) =
                (vec![Rgb::ZERO; tile.len()], vec![0; tile.len()], Counters::default());
            tracer.render_tile(
                &stage,
                &tile,
                &mut |i, v| {
                    got[i] = v;
                    handed_out[i] += 1;
                },
                &mut counters,
            );
            assert!(handed_out.iter().all(|&n| n == 1), "each sample handed out once: {handed_out:?}");
            rendered.push((got.iter().map(|c| c.to_array().map(f32::to_bits)).collect::<Vec<_>>(), counters.rays));
        }
        assert_eq!(rendered[0], rendered[1]);
        let lit = rendered[1].0.iter().filter(|v| v.iter().any(|&c| f32::from_bits(c) > 0.0)).count();
        assert!(lit > 200, "samples carried light");
    }
}
