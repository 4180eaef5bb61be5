//! One photon's flight: it leaves a light (`Tracing::launch`), and at each
//! hit is stored if its map keeps it and scattered by the surface, with
//! Russian roulette at diffuse surfaces (`Tracing::bounce`). Photon i's
//! random stream is fixed by (i, pass, seed). `trace` flies photons by
//! these two one at a time (`flying`), and `flight_lanes` eight at a time
//! as these two do.

use super::emit::{emit, emit_toward, EmittedPhoton, LightPicker, SpecularTargets};
use super::record::Photon;
use crate::faults::{self, Fault};
use crate::geometry::Ray;
use crate::render::world::materials::{Bsdf, Transport};
use crate::render::world::rng::{PassStreams, Sampler};
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

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

impl MapKind {
    /// The bounces, and of them the diffuse ones, a photon must have made
    /// before its map keeps it at a non-specular hit.
    #[inline(always)]
    pub(super) fn stores_after(self) -> (u32, u32) {
        match self {
            MapKind::Global => (0, 1),
            MapKind::Caustic | MapKind::Indirect => (1, 0),
            MapKind::All => (0, 0),
        }
    }
}

/// Keeps photon streams apart from camera streams with the same indices.
const PHOTON_SALT: u64 = 0x5eed_f07f_0000_0001;

/// What the photons of one call share.
pub(super) struct Tracing<'a> {
    world: &'a World,
    kind: MapKind,
    picker: LightPicker,
    /// Balls bounding the mirrors and glass (caustic maps only).
    targets: SpecularTargets,
    /// 1 / the photon count: each stored power's share.
    scale: f32,
    /// The most segments a photon flies: a path's, less the camera's one
    /// to the surface that gathers it.
    segments: u32,
    /// The photons' random streams in this pass.
    streams: PassStreams,
}

/// One photon between its bounces.
pub(super) struct Flight {
    pub(super) ray: Ray,
    pub(super) held: bool,
    pub(super) power: Rgb,
    pub(super) depth: u32,
    pub(super) diffuse_bounces: u32,
    pub(super) sampler: Sampler,
}

impl<'a> Tracing<'a> {
    /// For `count` photons of map `kind`: None if there is nothing to
    /// trace (no photons, no light, a caustic map without mirrors or glass).
    pub(super) fn new(
        world: &'a World,
        kind: MapKind,
        count: u64,
        pass: u64,
        seed: u64,
        max_depth: u32,
    ) -> Option<Self> {
        let picker = LightPicker::new(world);
        if picker.is_empty() || count == 0 {
            return None;
        }
        let targets = if kind == MapKind::Caustic { SpecularTargets::of(world) } else { SpecularTargets::default() };
        if kind == MapKind::Caustic && targets.is_empty() {
            return None;
        }
        let streams = PassStreams::new(pass, seed ^ PHOTON_SALT ^ kind as u64);
        let segments = max_depth.saturating_sub(1);
        Some(Tracing { world, kind, picker, targets, scale: 1.0 / count as f32, segments, streams })
    }

    pub(super) fn world(&self) -> &'a World {
        self.world
    }

    /// Each stored power's share: 1 / the photon count.
    pub(super) fn power_scale(&self) -> f32 {
        if faults::active(Fault::PhotonPowerHigh) {
            self.scale * 1.05
        } else {
            self.scale
        }
    }

    pub(super) fn picker(&self) -> &LightPicker {
        &self.picker
    }

    /// Photon `index`'s random stream.
    pub(super) fn stream(&self, index: u64) -> Sampler {
        self.streams.sampler(index)
    }

    pub(super) fn kind(&self) -> MapKind {
        self.kind
    }

    pub(super) fn segments(&self) -> u32 {
        self.segments
    }

    /// Photon `index`, leaving its light: None if it leaves none, or may
    /// not bounce at all.
    pub(super) fn launch(&self, index: u64) -> Option<Flight> {
        let world = self.world;
        let mut sampler = self.stream(index);
        let emitted = match self.kind {
            MapKind::Caustic => emit_toward(world, &self.picker, &self.targets, &mut sampler),
            _ => emit(world, &self.picker, &mut sampler),
        };
        let EmittedPhoton { ray, power } = emitted.filter(|_| self.segments > 0)?;
        let scale = self.power_scale();
        let held = world.holds(ray.origin);
        Some(Flight { ray, held, power: power * scale, depth: 0, diffuse_bounces: 0, sampler })
    }

    /// The photon's bounce at `hit`, the nearest along its ray: stored
    /// there if its map keeps it, then scattered by the surface. False
    /// once it goes no further.
    pub(super) fn bounce(&self, flight: &mut Flight, hit: &Hit, store: &mut impl FnMut(Photon)) -> bool {
        let kind = self.kind;
        let bsdf = Bsdf::new(self.world.material_of(hit));
        if !bsdf.is_specular() {
            let (bounces, diffuse_bounces) = kind.stores_after();
            let keep = flight.depth >= bounces && flight.diffuse_bounces >= diffuse_bounces;
            if keep && flight.power.is_finite() {
                store(Photon::new(hit.surface.point, flight.ray.direction, flight.power.to_array()));
            }
            if kind == MapKind::Caustic {
                return false;
            }
        }
        let sampler = &mut flight.sampler;
        let Some(scattered) = bsdf.sample(-flight.ray.direction, hit.surface.normal, sampler, Transport::Importance)
        else {
            return false;
        };
        if !scattered.delta {
            if kind == MapKind::Caustic {
                return false;
            }
            flight.diffuse_bounces += 1;
            // Russian roulette with the surface's reflectance: survivors carry
            // the absorbed photons' share
            let survive = scattered.weight.max_element().min(1.0);
            if survive <= 0.0 || sampler.next_f32() >= survive {
                return false;
            }
            flight.power *= scattered.weight / survive;
        } else {
            flight.power *= scattered.weight;
        }
        flight.ray = hit.surface.spawn_ray(scattered.wi);
        flight.depth += 1;
        flight.depth < self.segments
    }
}
