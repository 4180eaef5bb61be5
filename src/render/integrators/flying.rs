//! Items that fly from hit to hit on their own (photons, light and camera
//! subpaths), eight at a time: their rays meet the world in the paths'
//! eight-lane hit loop (`PathLanes::intersect8`), and each goes on from its
//! hit by itself, in scalar code. A lane whose item ends takes the next
//! one, so the lanes stay busy however far items go; items end out of
//! turn, so what they make is tagged with their place for `reorder`.

use std::ops::Range;

use super::path_lanes::PathLanes;
use crate::geometry::Ray;
use crate::render::world::lanes::{self, LANES};
use crate::render::world::{Hit, World};

/// Flies items `indices`: `launch` starts item i (None: it does not fly),
/// `ray` is its next ray and whether it started inside every wall (as
/// `World::intersect_held` takes it; asked once for each ray traced), and
/// `bounce` carries it on from the nearest hit (false: it ends there), told
/// the item's place in `indices`; told None where the ray meets nothing,
/// which ends the item whatever it says.
/// Eight at a time through `path_lanes` where given and the CPU has AVX2;
/// one at a time otherwise, with the same calls for each item in the same
/// order.
pub fn fly<T>(
    path_lanes: Option<&PathLanes>,
    world: &World,
    indices: Range<u64>,
    launch: impl FnMut(u64) -> Option<T>,
    ray: impl FnMut(&T) -> (Ray, bool),
    bounce: impl FnMut(u32, &mut T, Option<&Hit>) -> bool,
) {
    let Some(path_lanes) = path_lanes.filter(|_| PathLanes::runs_in_lanes()) else {
        return fly_one_at_a_time(world, indices, launch, ray, bounce);
    };
    #[cfg(target_arch = "x86_64")]
    // SAFETY: the CPU has AVX2 (`runs_in_lanes`).
    #[allow(unsafe_code)]
    return unsafe { fly_avx2(path_lanes, world, indices, launch, ray, bounce) };
    #[cfg(not(target_arch = "x86_64"))]
    fly_lanes(path_lanes, world, indices, launch, ray, bounce)
}

fn fly_one_at_a_time<T>(
    world: &World,
    indices: Range<u64>,
    mut launch: impl FnMut(u64) -> Option<T>,
    mut ray: impl FnMut(&T) -> (Ray, bool),
    mut bounce: impl FnMut(u32, &mut T, Option<&Hit>) -> bool,
) {
    for index in indices.clone() {
        let Some(mut item) = launch(index) else { continue };
        let place = (index - indices.start) as u32;
        loop {
            let (next, held) = ray(&item);
            let hit = world.intersect_held(&next, f32::INFINITY, held);
            if !bounce(place, &mut item, hit.as_ref()) || hit.is_none() {
                break;
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn fly_avx2<T>(
    path_lanes: &PathLanes,
    world: &World,
    indices: Range<u64>,
    launch: impl FnMut(u64) -> Option<T>,
    ray: impl FnMut(&T) -> (Ray, bool),
    bounce: impl FnMut(u32, &mut T, Option<&Hit>) -> bool,
) {
    fly_lanes(path_lanes, world, indices, launch, ray, bounce)
}

#[inline(always)]
fn fly_lanes<T>(
    path_lanes: &PathLanes,
    world: &World,
    indices: Range<u64>,
    mut launch: impl FnMut(u64) -> Option<T>,
    mut ray: impl FnMut(&T) -> (Ray, bool),
    mut bounce: impl FnMut(u32, &mut T, Option<&Hit>) -> bool,
) {
    let mut flying: [Option<(u32, T)>; LANES] = Default::default();
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
        let hits = path_lanes.intersect8(world, &rays);
        for (slot, hit) in flying.iter_mut().zip(&hits) {
            let Some((place, item)) = slot else { continue };
            if !bounce(*place, item, hit.as_ref()) || hit.is_none() {
                *slot = None;
            }
        }
    }
}
