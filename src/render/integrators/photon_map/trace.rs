//! Photon tracing: photons leave the lights, bounce by their surfaces' BSDFs
//! with Russian roulette at diffuse surfaces, and are stored at non-specular
//! hits according to which map they are for. Photon i's random stream is
//! fixed by (i, pass, seed), and chunks are joined in order, so the maps do
//! not depend on the thread count.

use rayon::prelude::*;

use crate::faults::{self, Fault};

use crate::render::integrators::photon_map::emit::{emit, emit_toward, specular_targets, EmittedPhoton, LightPicker};
use crate::render::integrators::photon_map::record::Photon;
use crate::render::world::bsdf::{Bsdf, Transport};
use crate::render::world::rng::Sampler;
use crate::render::world::World;

/// Which photons a map keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapKind {
    /// Jensen's global map for indirect light: stores after at least one
    /// diffuse bounce (direct light is sampled, caustics have their own map).
    Global,
    /// Light → one or more specular bounces → the first diffuse surface.
    Caustic,
    /// SPPM: every non-specular hit but the first (direct light is sampled).
    Indirect,
    /// Every non-specular hit, direct ones included (for inspecting the
    /// photon distribution itself).
    All,
}

/// Photons a task traces: the unit of work a cancel waits for at most.
pub const CHUNK: u64 = 4096;
/// Keeps photon streams apart from camera streams with the same indices.
const PHOTON_SALT: u64 = 0x5eed_f07f_0000_0001;

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
    let picker = LightPicker::new(world);
    if picker.is_empty() || count == 0 {
        return Some(Vec::new());
    }
    let targets = if kind == MapKind::Caustic { specular_targets(world) } else { Vec::new() };
    if kind == MapKind::Caustic && targets.is_empty() {
        return Some(Vec::new());
    }
    let scale = 1.0 / count as f32;
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
            let mut stored = Vec::new();
            for index in chunk * CHUNK..((chunk + 1) * CHUNK).min(count) {
                let mut sampler = Sampler::new(index, pass, seed ^ PHOTON_SALT ^ kind as u64);
                let emitted = match kind {
                    MapKind::Caustic => emit_toward(world, &picker, &targets, &mut sampler),
                    _ => emit(world, &picker, &mut sampler),
                };
                if let Some(photon) = emitted {
                    trace_one(world, kind, photon, scale, max_depth, &mut sampler, &mut stored);
                }
            }
            Some(stored)
        })
        .collect();
    Some(per_chunk?.concat())
}

fn trace_one(
    world: &World,
    kind: MapKind,
    emitted: EmittedPhoton,
    scale: f32,
    max_depth: u32,
    sampler: &mut Sampler,
    stored: &mut Vec<Photon>,
) {
    let EmittedPhoton { mut ray, mut power } = emitted;
    let held = world.holds(ray.origin);
    power *= if faults::active(Fault::PhotonPowerHigh) { scale * 1.05 } else { scale };
    let mut diffuse_bounces = 0;
    for depth in 0..max_depth {
        let Some(hit) = world.intersect_held(&ray, f32::INFINITY, held) else {
            return;
        };
        let bsdf = Bsdf::new(world.material_of(&hit));
        if !bsdf.is_specular() {
            let keep = match kind {
                MapKind::Global => diffuse_bounces > 0,
                MapKind::Caustic => depth > 0,
                MapKind::Indirect => depth > 0,
                MapKind::All => true,
            };
            if keep && power.is_finite() {
                stored.push(Photon::new(hit.surface.point, ray.direction, power.to_array()));
            }
            if kind == MapKind::Caustic {
                return;
            }
        }
        let Some(scattered) = bsdf.sample(-ray.direction, hit.surface.normal, sampler, Transport::Importance) else {
            return;
        };
        if !scattered.delta {
            if kind == MapKind::Caustic {
                return;
            }
            diffuse_bounces += 1;
            // Russian roulette with the surface's reflectance: survivors carry
            // the absorbed photons' share
            let survive = scattered.weight.max_element().min(1.0);
            if survive <= 0.0 || sampler.next_f32() >= survive {
                return;
            }
            power *= scattered.weight / survive;
        } else {
            power *= scattered.weight;
        }
        ray = hit.surface.spawn_ray(scattered.wi);
    }
}
