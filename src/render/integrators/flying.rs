//! Items that fly from hit to hit on their own (photons, light and camera
//! subpaths), eight at a time: their rays meet the world in the paths'
//! eight-lane hit loop (`LaneWorld::lane_hits`), and each goes on from its
//! hit by itself, in scalar code. A lane whose item ends takes the next
//! one, so the lanes stay busy however far items go; items end out of
//! turn, so what they make is tagged with their place for `reorder`.
//! What items draw at their hits (a light sample, a lens sample, the
//! direction they scatter into) and how the camera sees a hit may be
//! worked out in the lanes too (`DrawAtHits`).

use std::ops::Range;

use crate::geometry::Ray;
use crate::render::world::camera::CameraModel;
use crate::render::world::lane_world::{Given, LaneWorld, Want};
use crate::render::world::lanes::{self, LANES};
use crate::render::world::{Hit, World};

/// Flies items `indices`: `launch` starts item i (None: it does not fly),
/// `ray` is its next ray and whether it started inside every wall (as
/// `World::intersect_held` takes it; asked once for each ray traced), and
/// `bounce` carries it on from the nearest hit (false: it ends there), told
/// the item's place in `indices`; told None where the ray meets nothing,
/// which ends the item whatever it says.
/// Eight at a time through the `LaneWorld` where given and the CPU has AVX2;
/// one at a time otherwise, with the same calls for each item in the same
/// order.
pub fn fly<T>(
    lane_world: Option<&LaneWorld>,
    world: &World,
    indices: Range<u64>,
    launch: impl FnMut(u64) -> Option<T>,
    ray: impl FnMut(&T) -> (Ray, bool),
    mut bounce: impl FnMut(u32, &mut T, Option<&Hit>) -> bool,
) {
    let bounce = move |place, item: &mut T, hit: Option<&Hit>, _: Option<&Given>| bounce(place, item, hit);
    fly_drawing(lane_world, world, indices, launch, ray, NoDraws, bounce)
}

/// What items draw at their hits in the lanes (`LaneWorld::draw_at_hits`),
/// handed to their `bounce`; one at a time they draw alone, in `bounce`.
pub(crate) trait DrawAtHits<T> {
    /// What `item` asks to draw at its next hit (None: nothing), asked
    /// before its ray is traced.
    fn want(&self, item: &T) -> Option<Want>;
    /// The light chosen by a uniform number (`LightPicker::pick`), for
    /// items that sample lights.
    fn pick(&self, _u: f32) -> Option<(usize, f32)> {
        None
    }
    /// The camera, for items that join it.
    fn camera(&self) -> Option<&CameraModel> {
        None
    }
}

/// Items that draw nothing in the lanes.
pub(crate) struct NoDraws;

impl<T> DrawAtHits<T> for NoDraws {
    fn want(&self, _: &T) -> Option<Want> {
        None
    }
}

/// `fly`, with what `draws` asks for drawn in the lanes and handed to
/// `bounce` (None: the item draws alone).
pub(crate) fn fly_drawing<T>(
    lane_world: Option<&LaneWorld>,
    world: &World,
    indices: Range<u64>,
    launch: impl FnMut(u64) -> Option<T>,
    ray: impl FnMut(&T) -> (Ray, bool),
    draws: impl DrawAtHits<T>,
    bounce: impl FnMut(u32, &mut T, Option<&Hit>, Option<&Given>) -> bool,
) {
    let Some(lane_world) = lane_world else {
        return fly_one_at_a_time(world, indices, launch, ray, bounce);
    };
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the CPU has AVX2: a `LaneWorld` is made only where it does.
    #[allow(unsafe_code)]
    return unsafe { fly_avx2(lane_world, world, indices, launch, ray, draws, bounce) };
    #[cfg(not(target_arch = "x86_64"))]
    fly_lanes(lane_world, world, indices, launch, ray, draws, bounce)
}

fn fly_one_at_a_time<T>(
    world: &World,
    indices: Range<u64>,
    mut launch: impl FnMut(u64) -> Option<T>,
    mut ray: impl FnMut(&T) -> (Ray, bool),
    mut bounce: impl FnMut(u32, &mut T, Option<&Hit>, Option<&Given>) -> bool,
) {
    for index in indices.clone() {
        let Some(mut item) = launch(index) else { continue };
        let place = (index - indices.start) as u32;
        loop {
            let (next, held) = ray(&item);
            let hit = world.intersect_held(&next, f32::INFINITY, held);
            if !bounce(place, &mut item, hit.as_ref(), None) || hit.is_none() {
                break;
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn fly_avx2<T>(
    lane_world: &LaneWorld,
    world: &World,
    indices: Range<u64>,
    launch: impl FnMut(u64) -> Option<T>,
    ray: impl FnMut(&T) -> (Ray, bool),
    draws: impl DrawAtHits<T>,
    bounce: impl FnMut(u32, &mut T, Option<&Hit>, Option<&Given>) -> bool,
) {
    fly_lanes(lane_world, world, indices, launch, ray, draws, bounce)
}

#[inline(always)]
fn fly_lanes<T>(
    lane_world: &LaneWorld,
    world: &World,
    indices: Range<u64>,
    mut launch: impl FnMut(u64) -> Option<T>,
    mut ray: impl FnMut(&T) -> (Ray, bool),
    draws: impl DrawAtHits<T>,
    mut bounce: impl FnMut(u32, &mut T, Option<&Hit>, Option<&Given>) -> bool,
) {
    let mut flying: [Option<(u32, T)>; LANES] = Default::default();
    let mut given: [Option<Given>; LANES] = [None; LANES];
    let mut next = indices.start;
    loop {
        for slot in flying.iter_mut().filter(|f| f.is_none()) {
            while slot.is_none() && next < indices.end {
                *slot = launch(next).map(|item| ((next - indices.start) as u32, item));
                next += 1;
            }
        }
        if flying.iter().all(Option::is_none) {
            return;
        }
        let rays = lanes::each(|i| flying[i].as_ref().map(|(_, item)| ray(item)));
        let wants = lanes::each(|i| flying[i].as_ref().and_then(|(_, item)| draws.want(item)));
        let (lane_hits, direction) = lane_world.lane_hits(&rays);
        let drawn = wants.iter().any(Option::is_some);
        if drawn {
            let pick = |u| draws.pick(u);
            lane_world.draw_at_hits(world, &lane_hits, direction, &wants, &pick, draws.camera(), &mut given);
        }
        let hits = lane_world.hits_of(world, &lane_hits);
        for ((slot, hit), given) in flying.iter_mut().zip(&hits).zip(&given) {
            let Some((place, item)) = slot else { continue };
            let given = given.as_ref().filter(|_| drawn);
            if !bounce(*place, item, hit.as_ref(), given) || hit.is_none() {
                *slot = None;
            }
        }
    }
}
