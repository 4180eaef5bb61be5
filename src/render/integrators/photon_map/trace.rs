//! Photon tracing: photons leave the lights, bounce by their surfaces' BSDFs
//! with Russian roulette at diffuse surfaces, and are stored at non-specular
//! hits according to which map they are for. Photon i's random stream is
//! fixed by (i, pass, seed), and chunks are joined in order, so the maps do
//! not depend on the thread count. Eight photons are traced at a time
//! where the CPU and the world allow (`flight_lanes`; one at a time
//! through `flying` otherwise), then put back in photon order
//! (`reorder`): the same maps, bit for bit.

use std::ops::Range;

use rayon::prelude::*;

pub use super::flight::MapKind;
use super::flight::{Flight, Tracing};
use super::record::Photon;
use crate::render::integrators::{flying, reorder};
use crate::render::world::lane_world::LaneWorld;
use crate::render::world::{Hit, World};

/// Photons a task traces: the unit of work a cancel waits for at most.
pub const CHUNK: u64 = 4096;

/// Which photons to trace: for which map, how many (stored powers are
/// divided by the count), the pass and seed that fix their random streams,
/// and the longest path.
#[derive(Clone, Copy, Debug)]
pub struct PhotonBatch {
    pub kind: MapKind,
    pub count: u64,
    pub pass: u64,
    pub seed: u64,
    /// The longest path, camera to light (`RenderSettings::max_depth`).
    pub max_depth: u32,
}

/// Trace `batch` through `world` (eight at a time where the lanes run).
pub fn trace_photons(world: &World, batch: PhotonBatch) -> Vec<Photon> {
    let (lanes, mut photons) = (LaneWorld::new(world), Vec::new());
    trace_photons_until(world, lanes.as_ref(), batch, &|| true, &mut photons);
    photons
}

/// `trace_photons` into `photons` (emptied first), asking `keep_going`
/// before each chunk of photons: None once it says no, after no more than
/// the chunks already being traced (one a worker). `photons` keeps its
/// memory from call to call: SPPM traces each pass into the last pass's
/// array, whose pages are then there already (a million photons' array,
/// 70 MB, is beyond what the heap keeps, `engine::keep_freed_memory`).
/// Eight at a time through `lanes` where given.
pub fn trace_photons_until(
    world: &World,
    lanes: Option<&LaneWorld>,
    batch: PhotonBatch,
    keep_going: &(dyn Fn() -> bool + Sync),
    photons: &mut Vec<Photon>,
) -> Option<()> {
    photons.clear();
    let PhotonBatch { kind, count, pass, seed, max_depth } = batch;
    let Some(tracing) = Tracing::new(world, kind, count, pass, seed, max_depth) else {
        return Some(());
    };
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
            let indices = chunk * CHUNK..((chunk + 1) * CHUNK).min(count);
            Some(trace_chunk(lanes, &tracing, indices))
        })
        .collect();
    let per_chunk = per_chunk?;
    photons.reserve(per_chunk.iter().map(Vec::len).sum());
    for chunk in &per_chunk {
        photons.extend_from_slice(chunk);
    }
    Some(())
}

/// The photons `indices`: what they store, in photon order. Eight at a
/// time through the `LaneWorld` where given, with the same records bit for
/// bit.
fn trace_chunk(lane_world: Option<&LaneWorld>, tracing: &Tracing, indices: Range<u64>) -> Vec<Photon> {
    // Each stored photon, and its photon's place among `indices`
    let (mut stored, mut places) = (Vec::new(), Vec::new());
    let items = (indices.end - indices.start) as usize;
    match lane_world {
        Some(lane_world) => tracing.fly_in_lanes(lane_world, indices, |place, photon| {
            stored.push(photon);
            places.push(place);
        }),
        None => {
            let bounce = |place, flight: &mut Flight, hit: Option<&Hit>| {
                hit.is_some_and(|hit| {
                    tracing.bounce(flight, hit, &mut |photon| {
                        stored.push(photon);
                        places.push(place);
                    })
                })
            };
            let ray = |flight: &Flight| (flight.ray, flight.held);
            flying::fly(None, tracing.world(), indices, |index| tracing.launch(index), ray, bounce);
        }
    }
    reorder::by_item(&stored, &places, items).0
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::World;
    use crate::scene::{presets, Attenuation, Light, LightKind, Object, Rgb, Scene, Shape, ValidScene};

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
        let lanes = LaneWorld::new(&world).expect("a world the lanes trace");
        let mut stored = 0;
        for kind in [MapKind::Global, MapKind::Caustic, MapKind::Indirect, MapKind::All] {
            for pass in 0..2 {
                let Some(tracing) = Tracing::new(&world, kind, 20_000, pass, 20_261_201, max_depth) else { continue };
                // Away from 0 and not a multiple of eight
                let indices = 1000..5099;
                let one_by_one = trace_chunk(None, &tracing, indices.clone());
                let eight = trace_chunk(Some(&lanes), &tracing, indices);
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
        assert!(LaneWorld::runs_in_lanes(), "this CPU lacks AVX2: the lanes would be the scalar code here");
        for name in presets::names() {
            let stored = assert_lanes_store_what_one_by_one_does(name, preset(name), 16);
            assert!(stored > 1000, "{name}: only {stored} photons stored");
        }
    }

    /// Lights of every kind the lanes emit from, one, two and three of a
    /// kind (splat, blended, gathered lane by lane), beside spots, which
    /// emit lane by lane: smallpt's room with balls, caps and triangles
    /// glowing, and point lights and spots.
    #[test]
    fn every_kind_of_light_emits_the_same_photons() {
        let mut scene = preset("smallpt");
        let light = |name: &str, kind| Light {
            name: name.into(),
            kind,
            color: Rgb::ONE,
            intensity: 2000.0,
            attenuation: Attenuation::default(),
            enabled: true,
        };
        let glowing = |scene: &mut Scene, name: &str, shape| {
            scene.objects.push(Object { name: name.into(), shape, ..scene.objects[8].clone() });
        };
        let panel = |x: f32, y: f32, z: f32| Shape::Triangle {
            a: Vec3::new(x, y, z),
            b: Vec3::new(x + 20.0, y, z),
            c: Vec3::new(x + 10.0, y, z + 20.0),
        };
        let spot = |x: f32| LightKind::Spot {
            position: Vec3::new(x, 70.0, 60.0),
            direction: Vec3::new(0.0, -1.0, 0.2),
            cone_angle_degrees: 30.0,
            falloff_exponent: 4.0,
        };
        for (k, x) in [20.0f32, 45.0, 70.0].into_iter().enumerate() {
            let stored = assert_lanes_store_what_one_by_one_does("smallpt and lights", scene.clone(), 16);
            assert!(stored > 1000, "{k} of each kind: only {stored} photons stored");
            glowing(&mut scene, &format!("glow {k}"), Shape::Sphere { center: Vec3::new(x, 30.0, 100.0), radius: 3.0 });
            glowing(
                &mut scene,
                &format!("cap {k}"),
                Shape::Sphere { center: Vec3::new(x, 681.0, 100.0), radius: 600.0 },
            );
            glowing(&mut scene, &format!("panel {k}"), panel(x, 70.0, 60.0));
            scene.lights.push(light(&format!("point {k}"), LightKind::Point { position: Vec3::new(x, 60.0, 90.0) }));
            scene.lights.push(light(&format!("spot {k}"), spot(x)));
        }
        let stored = assert_lanes_store_what_one_by_one_does("smallpt and lights", scene, 16);
        assert!(stored > 1000, "three of each kind: only {stored} photons stored");
    }

    /// Photons that end at the depth cap, or before any bounce: paths of
    /// one segment leave none for a photon.
    #[test]
    fn short_flights_end_at_the_depth_cap() {
        for depth in [0, 1, 2, 3] {
            let stored = assert_lanes_store_what_one_by_one_does("caustics", preset("caustics"), depth);
            assert_eq!(stored == 0, depth <= 1, "depth {depth}: {stored} photons stored");
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
