//! Path tracing: physically based BSDFs, next-event estimation toward one
//! light per bounce, multiple importance sampling between light and BSDF
//! sampling for area lights, Russian roulette.

use super::bsdf::{Bsdf, Transport};
use super::light::area_pdf;
use super::occluders::Occluders;
use super::rng::Sampler;
use super::sampling::power_heuristic;
use super::world::World;
use super::Counters;
use crate::geometry::Ray;
use crate::scene::Rgb;

/// Bounces before Russian roulette may end a path.
pub(crate) const ROULETTE_DEPTH: u32 = 3;

pub fn radiance(world: &World, ray: &Ray, max_depth: u32, sampler: &mut Sampler, counters: &mut Counters) -> Rgb {
    let occluders = Occluders::for_path(world, ray.origin);
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
        let Some(hit) = world.intersect(&ray, f32::INFINITY) else {
            radiance += throughput * world.background;
            break;
        };
        let wo = -ray.direction;

        // Emission reached by this ray, weighted against light sampling
        let emitted = world.emitted(&hit, wo);
        if emitted != Rgb::ZERO {
            let weight = match world.objects[hit.object as usize].light {
                Some(_) if !after_delta => {
                    power_heuristic(last_pdf, pick_pdf * area_pdf(world, hit.object, last_point, &hit.surface))
                }
                _ => 1.0,
            };
            radiance += throughput * emitted * weight;
        }

        let bsdf = Bsdf::new(world.material_of(&hit));
        let n = hit.surface.normal;
        let facing = if wo.dot(n) < 0.0 { -n } else { n };

        // Next-event estimation: one light, chosen uniformly
        if !bsdf.is_specular() && light_count > 0 {
            let pick = match light_count {
                1 => 0,
                _ => ((sampler.next_f32() * light_count as f32) as usize).min(light_count - 1),
            };
            let light = &world.lights[pick];
            if let Some(sample) = light.sample(world, &hit.surface, sampler.next_2d()) {
                let f = bsdf.eval(wo, sample.wi, facing);
                if f != Rgb::ZERO {
                    counters.rays += 1;
                    if !occluders.blocks(&sample) {
                        let weight = if light.is_delta() {
                            1.0
                        } else {
                            power_heuristic(pick_pdf * sample.pdf, bsdf.pdf(wo, sample.wi, facing))
                        };
                        radiance += throughput * f * sample.value * (sample.wi.dot(facing) * weight / pick_pdf);
                    }
                }
            }
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
            throughput /= survive;
        }
        ray = hit.surface.spawn_ray(scattered.wi);
    }
    radiance
}
