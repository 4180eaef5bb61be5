//! The state of eight paths in flight, and how a lane takes the next
//! sample and hands out the one it finished.

use glam::Vec3;

use super::samples::CameraSamples;
use crate::render::world::lanes::{Count8, Rng8, F8, LANES, M8, V8};
use crate::scene::Rgb;

/// Eight paths in flight.
pub(super) struct Lanes {
    pub(super) active: M8,
    pub(super) depth: Count8,
    pub(super) inside_walls: M8,
    pub(super) origin: V8,
    pub(super) direction: V8,
    pub(super) throughput: V8,
    pub(super) radiance: V8,
    pub(super) after_delta: M8,
    pub(super) last_pdf: F8,
    pub(super) last_point: V8,
    pub(super) rng: Rng8,
}

impl Lanes {
    pub(super) fn new() -> Self {
        let zero = V8::splat(Vec3::ZERO);
        Lanes {
            active: M8::NONE,
            depth: Count8::ZERO,
            inside_walls: M8::NONE,
            origin: zero,
            direction: zero,
            throughput: zero,
            radiance: zero,
            after_delta: M8::NONE,
            last_pdf: F8::splat(0.0),
            last_point: zero,
            rng: Rng8::new(),
        }
    }

    /// Idle lanes take the next samples (from `next` on, below `count`):
    /// each sample's fields blended into its lane, the registers staying
    /// registers, not gathered for all eight lanes nor written lane by lane
    /// into arrays and loaded back.
    #[inline(always)]
    pub(super) fn start_idle(
        &mut self,
        samples: &CameraSamples,
        slots: &mut [usize; LANES],
        next: &mut usize,
        count: usize,
    ) {
        let mut idle = (!self.active).bits();
        let mut started = M8::NONE;
        let (mut origin, mut direction, mut inside_walls) = (self.origin, self.direction, self.inside_walls);
        while idle != 0 && *next < count {
            let lane = idle.trailing_zeros() as usize;
            idle &= idle - 1;
            let (eight, i) = (&samples.0[*next / LANES], *next % LANES);
            let (sample_origin, sample_direction) = eight.ray(i);
            let here = M8::only(lane);
            started = started.or(here);
            origin = here.select_v(V8::splat(sample_origin), origin);
            direction = here.select_v(V8::splat(sample_direction), direction);
            inside_walls = here.select_mask(M8::splat(eight.inside_walls >> i & 1 != 0), inside_walls);
            self.rng.start(lane, eight.stream[i], eight.ahead[i]);
            slots[lane] = *next;
            *next += 1;
        }
        if !started.any() {
            return;
        }
        self.active = self.active.or(started);
        self.depth = self.depth.reset(started);
        self.inside_walls = inside_walls;
        self.origin = origin;
        self.direction = direction;
        self.throughput = started.select_v(V8::splat(Rgb::ONE), self.throughput);
        self.radiance = started.select_v(V8::splat(Rgb::ZERO), self.radiance);
        self.after_delta = self.after_delta.or(started);
        self.last_pdf = started.select(F8::splat(0.0), self.last_pdf);
        self.last_point = started.select_v(origin, self.last_point);
    }

    /// Paths of `mask` are done: their radiance goes out, their lanes free up.
    #[inline(always)]
    pub(super) fn finish(&mut self, mask: M8, slots: &[usize; LANES], out: &mut impl FnMut(usize, Rgb)) {
        let mut done = mask.bits();
        if done == 0 {
            return;
        }
        let (x, y, z) = (self.radiance.x.to_array(), self.radiance.y.to_array(), self.radiance.z.to_array());
        while done != 0 {
            let lane = done.trailing_zeros() as usize;
            done &= done - 1;
            out(slots[lane], Rgb::new(x[lane], y[lane], z[lane]));
        }
        self.active = self.active.and_not(mask);
    }
}
