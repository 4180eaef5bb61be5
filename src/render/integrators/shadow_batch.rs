//! Shadow rays asked for as a path goes and traced later, all at once and
//! eight at a time (`LaneWorld::shadows_blocked`). A caller keeps what each
//! would let through and adds it, in the order it was found, once the batch
//! says what is blocked: the same sums as tracing each ray at once.

use crate::render::world::lane_world::LaneWorld;
use crate::render::world::occluders::Shadow;
use crate::render::world::World;

#[derive(Default)]
pub struct ShadowBatch {
    shadows: Vec<Shadow>,
    blocked: Vec<bool>,
}

impl ShadowBatch {
    /// Ask for `shadow`; its index for `blocked`.
    #[inline]
    pub fn push(&mut self, shadow: Shadow) -> u32 {
        self.shadows.push(shadow);
        self.shadows.len() as u32 - 1
    }

    /// Ask for every one of `shadows` (emptied); the index of the first.
    pub fn append(&mut self, shadows: &mut Vec<Shadow>) -> u32 {
        let first = self.count();
        self.shadows.append(shadows);
        first
    }

    /// How many are asked for.
    #[inline]
    pub fn count(&self) -> u32 {
        self.shadows.len() as u32
    }

    /// Trace every ray asked for since `clear`: through `lanes` where given,
    /// else one at a time.
    pub fn trace(&mut self, lanes: Option<&LaneWorld>, world: &World) {
        self.blocked.clear();
        self.blocked.resize(self.shadows.len(), false);
        match lanes {
            Some(lanes) => lanes.shadows_blocked(&self.shadows, &mut self.blocked),
            None => (self.shadows.iter().zip(&mut self.blocked)).for_each(|(shadow, out)| *out = world.blocked(shadow)),
        }
    }

    /// Whether something blocks ray `index` (after `trace`).
    #[inline]
    pub fn blocked(&self, index: u32) -> bool {
        self.blocked[index as usize]
    }

    pub fn clear(&mut self) {
        self.shadows.clear();
        self.blocked.clear();
    }
}
