//! Photon tracing eight photons at a time: their rays meet the world in
//! the paths' eight-lane hit loop (`PathLanes::intersect8`), and each
//! photon bounces on by itself (`Tracing::bounce`), on its own random
//! stream. A lane whose photon ends takes the next one, so the lanes stay
//! busy however far photons go. What a chunk stores is put back into
//! photon order (`reorder`), so the map is the one traced one photon at a
//! time, bit for bit.

use std::ops::Range;

use super::flight::{Flight, Tracing};
use super::record::Photon;
use crate::render::integrators::path_lanes::PathLanes;
use crate::render::integrators::reorder;
use crate::render::world::lanes::{self, LANES};

/// The photons `indices`, eight at a time: what they store, in photon
/// order, as `Tracing::trace_one_by_one` stores it.
pub(super) fn trace_chunk(path_lanes: &PathLanes, tracing: &Tracing, indices: Range<u64>) -> Vec<Photon> {
    if !PathLanes::runs_in_lanes() {
        return tracing.trace_one_by_one(indices);
    }
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the CPU has AVX2 (`runs_in_lanes`).
    #[allow(unsafe_code)]
    return unsafe { trace_chunk_avx2(path_lanes, tracing, indices) };
    #[cfg(not(target_arch = "x86_64"))]
    trace_chunk_lanes(path_lanes, tracing, indices)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn trace_chunk_avx2(path_lanes: &PathLanes, tracing: &Tracing, indices: Range<u64>) -> Vec<Photon> {
    trace_chunk_lanes(path_lanes, tracing, indices)
}

#[inline(always)]
fn trace_chunk_lanes(path_lanes: &PathLanes, tracing: &Tracing, indices: Range<u64>) -> Vec<Photon> {
    let start = indices.start;
    // Each stored photon, and its photon's place in the chunk
    let (mut stored, mut places) = (Vec::new(), Vec::new());
    let mut flights: [Option<(u32, Flight)>; LANES] = Default::default();
    let mut next = indices.start;
    loop {
        for flight in flights.iter_mut().filter(|f| f.is_none()) {
            while flight.is_none() && next < indices.end {
                *flight = tracing.launch(next).map(|f| ((next - start) as u32, f));
                next += 1;
            }
        }
        if flights.iter().all(Option::is_none) {
            break;
        }
        let rays = lanes::each(|i| flights[i].as_ref().map(|(_, f)| (f.ray, f.held)));
        let hits = path_lanes.intersect8(tracing.world(), &rays);
        for (slot, hit) in flights.iter_mut().zip(&hits) {
            let Some((place, flight)) = slot else { continue };
            let goes_on = match hit {
                Some(hit) => tracing.bounce(flight, hit, &mut |photon| stored.push(photon)),
                None => false,
            };
            places.resize(stored.len(), *place);
            if !goes_on {
                *slot = None;
            }
        }
    }
    reorder::by_item(&stored, &places, (indices.end - start) as usize).0
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::integrators::photon_map::flight::MapKind;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::World;
    use crate::scene::{presets, Attenuation, Light, LightKind, Rgb, Scene, ValidScene};

    fn preset(name: &str) -> Scene {
        presets::preset(name).and_then(Result::ok).expect("preset").into_scene()
    }

    /// Each map's photons of `scene`, eight at a time and one at a time:
    /// the same records, bit for bit, in the same order. Returns how many
    /// were stored.
    fn assert_lanes_store_what_one_by_one_does(name: &str, scene: Scene, max_depth: u32) -> usize {
        let scene = ValidScene::new(scene).expect("a valid scene");
        // As a render builds it: walls anchored where the camera looks
        let camera = CameraModel::new(&scene.camera, 64, 48);
        let (world, _) = World::for_view(&scene, &camera, 64, 48);
        let lanes = PathLanes::new(&world).expect("a world the lanes trace");
        let mut stored = 0;
        for kind in [MapKind::Global, MapKind::Caustic, MapKind::Indirect, MapKind::All] {
            for pass in 0..2 {
                let Some(tracing) = Tracing::new(&world, kind, 20_000, pass, 20_261_201, max_depth) else { continue };
                // Away from 0 and not a multiple of eight
                let indices = 1000..5099;
                let one_by_one = tracing.trace_one_by_one(indices.clone());
                let eight = trace_chunk(&lanes, &tracing, indices);
                let bytes = |photons: &[Photon]| photons.iter().map(Photon::to_bytes).collect::<Vec<_>>();
                let same = bytes(&one_by_one) == bytes(&eight);
                assert!(same, "{name}, {kind:?}, pass {pass}, depth {max_depth}: the maps differ");
                stored += eight.len();
            }
        }
        stored
    }

    #[test]
    fn every_preset_stores_what_one_photon_at_a_time_stores() {
        assert!(PathLanes::runs_in_lanes(), "this CPU lacks AVX2: the lanes would be the scalar code here");
        for name in presets::names() {
            let stored = assert_lanes_store_what_one_by_one_does(name, preset(name), 16);
            assert!(stored > 1000, "{name}: only {stored} photons stored");
        }
    }

    /// Photons that end at the depth cap, or before any bounce.
    #[test]
    fn short_flights_end_at_the_depth_cap() {
        for depth in [0, 1, 2, 3] {
            let stored = assert_lanes_store_what_one_by_one_does("caustics", preset("caustics"), depth);
            assert_eq!(stored == 0, depth == 0, "depth {depth}: {stored} photons stored");
        }
    }

    /// Lights outside the walls (photons that start outside and enter the
    /// room from either side of a wall), a directional light and the sky,
    /// whose photons start outside the scene.
    #[test]
    fn photons_from_outside_the_walls_store_the_same() {
        let light = |name: &str, kind: LightKind, intensity: f32| Light {
            name: name.into(),
            kind,
            color: Rgb::ONE,
            intensity,
            attenuation: Attenuation::default(),
            enabled: true,
        };
        for name in ["cornell", "smallpt"] {
            let mut scene = preset(name);
            let outside = scene.camera.position + Vec3::new(0.0, 0.0, 5.0) * scene.camera.position.length().max(1.0);
            scene.lights.push(light("outside", LightKind::Point { position: outside }, 1e4));
            scene.lights.push(light("sun", LightKind::Directional { direction: Vec3::new(0.2, -1.0, -0.3) }, 1.0));
            scene.background = Rgb::new(0.2, 0.3, 0.4);
            let world = World::new(&ValidScene::new(scene.clone()).expect("a valid scene"));
            assert!(!world.holds(outside), "{name}: the light is outside the walls");
            let stored = assert_lanes_store_what_one_by_one_does(name, scene, 16);
            // Smallpt's walls are spheres: what comes from outside stays outside
            assert!(stored > 200, "{name}: only {stored} photons stored");
        }
    }
}
