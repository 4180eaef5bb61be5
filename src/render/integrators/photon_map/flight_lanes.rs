//! Photons eight at a time, as `Tracing::launch` and `Tracing::bounce`
//! send them one at a time: eight leave their lights at once (the light
//! each picks, lane by lane; where it leaves it, in the lanes), then bounce
//! in the lanes (their map's rule for storing, the surfaces' scattering
//! shared with the path tracer, Russian roulette at diffuse surfaces). The
//! same photons bit for bit, each stored in the order its photon meets its
//! surfaces. A lane whose photon ends takes the next one.

use std::ops::Range;

use glam::Vec3;

use super::flight::{MapKind, Tracing};
use super::record::Photon;
use crate::geometry::offset_origin;
use crate::render::world::lane_world::{LaneWorld, Scattered};
use crate::render::world::lanes::{Count8, Rng8, F8, LANES, M8, V8};
use crate::render::world::materials::Transport;

/// Eight photons between their bounces (`Flight`).
struct PhotonLanes {
    active: M8,
    held: M8,
    origin: V8,
    direction: V8,
    power: V8,
    depth: Count8,
    diffuse_bounces: Count8,
    rng: Rng8,
    /// Each lane's photon, by its place in the indices traced.
    place: [u32; LANES],
}

impl PhotonLanes {
    /// Lanes `started` take photons that leave `origin` along `direction`
    /// carrying `power`, their streams in `rng` (the other lanes' as they were).
    #[inline(always)]
    fn start(&mut self, started: M8, held: M8, origin: V8, direction: V8, power: V8, rng: Rng8) {
        self.active = self.active.or(started);
        self.held = started.select_mask(held, self.held);
        self.origin = started.select_v(origin, self.origin);
        self.direction = started.select_v(direction, self.direction);
        self.power = started.select_v(power, self.power);
        self.depth = self.depth.reset(started);
        self.diffuse_bounces = self.diffuse_bounces.reset(started);
        self.rng = rng;
    }
}

impl Tracing<'_> {
    /// Photons `indices` through the `LaneWorld`, each stored photon told to
    /// `store` with its photon's place in `indices`.
    pub(super) fn fly_in_lanes(&self, lane_world: &LaneWorld, indices: Range<u64>, store: impl FnMut(u32, Photon)) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has AVX2: a `LaneWorld` is made only where it does.
        #[allow(unsafe_code)]
        unsafe {
            self.fly_avx2(lane_world, indices, store)
        };
        #[cfg(not(target_arch = "x86_64"))]
        self.fly_lanes(lane_world, indices, store);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn fly_avx2(&self, lane_world: &LaneWorld, indices: Range<u64>, store: impl FnMut(u32, Photon)) {
        self.fly_lanes(lane_world, indices, store);
    }

    #[inline(always)]
    fn fly_lanes(&self, lane_world: &LaneWorld, indices: Range<u64>, mut store: impl FnMut(u32, Photon)) {
        let zero = V8::splat(Vec3::ZERO);
        let mut st = PhotonLanes {
            active: M8::NONE,
            held: M8::NONE,
            origin: zero,
            direction: zero,
            power: zero,
            depth: Count8::ZERO,
            diffuse_bounces: Count8::ZERO,
            rng: Rng8::new(),
            place: [0; LANES],
        };
        let mut next = indices.start;
        loop {
            self.launch_idle(lane_world, &mut st, &mut next, &indices);
            if !st.active.any() {
                return;
            }
            self.bounce_lanes(lane_world, &mut st, &mut store);
        }
    }

    /// Idle lanes take the next photons, all at once: their streams' first
    /// draws, the light each picks (lane by lane) and where it leaves that
    /// light (`LaneWorld::emit`), as `Tracing::launch` has them. Caustic
    /// photons, which aim at the mirrors and glass, leave one by one.
    #[inline(always)]
    fn launch_idle(&self, lane_world: &LaneWorld, st: &mut PhotonLanes, next: &mut u64, indices: &Range<u64>) {
        if self.kind() == MapKind::Caustic {
            return self.launch_one_by_one(st, next, indices);
        }
        if self.segments() == 0 {
            *next = indices.end;
            return;
        }
        // Again while photons leave no light (one of no power picked)
        loop {
            let mut idle = (!st.active).bits();
            if idle == 0 || *next >= indices.end {
                return;
            }
            let mut states = st.rng.states();
            let mut drawn = 0;
            while idle != 0 && *next < indices.end {
                let lane = idle.trailing_zeros() as usize;
                idle &= idle - 1;
                drawn |= 1 << lane;
                states[lane] = self.stream(*next).state();
                st.place[lane] = (*next - indices.start) as u32;
                *next += 1;
            }
            let drawn = M8::from_bits(drawn);
            let mut rng = Rng8::from_states(states);
            let u_pick = rng.next_f32(drawn).to_array();
            let (mut light, mut probability, mut picked) = ([0; LANES], [1.0; LANES], 0);
            for lane in drawn.lanes() {
                if let Some((index, p)) = self.picker().pick(u_pick[lane]) {
                    (light[lane], probability[lane]) = (index, p);
                    picked |= 1 << lane;
                }
            }
            let started = M8::from_bits(picked);
            let (u1, u2) = (rng.next_2d(started), rng.next_2d(started));
            let emitted = lane_world.emit(self.world(), &light, started, u1, u2);
            let power = emitted.power / F8::from_array(probability) * F8::splat(self.power_scale());
            let mut held = 0;
            for lane in started.lanes() {
                held |= (self.world().holds(emitted.origin.lane(lane)) as u32) << lane;
            }
            st.start(started, M8::from_bits(held), emitted.origin, emitted.direction, power, rng);
        }
    }

    /// `launch_idle` by `Tracing::launch`, photon by photon.
    #[inline(always)]
    fn launch_one_by_one(&self, st: &mut PhotonLanes, next: &mut u64, indices: &Range<u64>) {
        let mut idle = (!st.active).bits();
        let mut started = 0;
        let mut states = st.rng.states();
        let (mut origin, mut direction, mut power) = ([Vec3::ZERO; LANES], [Vec3::ZERO; LANES], [Vec3::ZERO; LANES]);
        let mut held = [false; LANES];
        while idle != 0 && *next < indices.end {
            let index = *next;
            *next += 1;
            let Some(flight) = self.launch(index) else { continue };
            let lane = idle.trailing_zeros() as usize;
            idle &= idle - 1;
            started |= 1 << lane;
            st.place[lane] = (index - indices.start) as u32;
            states[lane] = flight.sampler.state();
            (origin[lane], direction[lane], power[lane]) = (flight.ray.origin, flight.ray.direction, flight.power);
            held[lane] = flight.held;
        }
        if started == 0 {
            return;
        }
        let (origin, direction, power) =
            (V8::from_fn(|i| origin[i]), V8::from_fn(|i| direction[i]), V8::from_fn(|i| power[i]));
        let held = M8::from_fn(|i| held[i]);
        st.start(M8::from_bits(started), held, origin, direction, power, Rng8::from_states(states));
    }

    /// `Tracing::bounce` for every photon in flight, at its ray's nearest
    /// hit; photons that end leave their lanes idle.
    #[inline(always)]
    fn bounce_lanes(&self, lane_world: &LaneWorld, st: &mut PhotonLanes, store: &mut impl FnMut(u32, Photon)) {
        let (hits, surfaces) = lane_world.hit_surfaces(st.active, st.held, st.origin, st.direction);
        let found = hits.found;
        // Stored at non-specular hits, by the map's rule, if finite
        let specular = surfaces.specular();
        let (bounces, diffuse_bounces) = self.kind().stores_after();
        let finite = st.power.x.is_finite().and(st.power.y.is_finite()).and(st.power.z.is_finite());
        let keep = st.depth.ge(bounces).and(st.diffuse_bounces.ge(diffuse_bounces));
        let stored = found.and_not(specular).and(keep).and(finite);
        for lane in stored.lanes() {
            let photon = Photon::new(hits.point.lane(lane), st.direction.lane(lane), st.power.lane(lane).to_array());
            store(st.place[lane], photon);
        }
        let wo = -st.direction;
        let normal = hits.normal;
        let facing = normal.dot(wo).lt(F8::splat(0.0)).select_v(-normal, normal);
        let Scattered { go, delta, wi, weight, .. } =
            surfaces.scatter(&mut st.rng, wo, normal, facing, Transport::Importance);
        // A caustic photon ends at the first surface that is not a mirror or glass
        let go = if self.kind() == MapKind::Caustic { go.and(specular) } else { go };
        // Russian roulette with the surface's reflectance: survivors carry
        // the absorbed photons' share
        let diffuse = go.and_not(delta);
        st.diffuse_bounces = st.diffuse_bounces.count_in(diffuse);
        let zero = F8::splat(0.0);
        let survive = weight.max_element().min(F8::splat(1.0));
        let dark = diffuse.and(survive.le(zero));
        let roulette = diffuse.and_not(dark);
        let u = st.rng.next_f32(roulette);
        let go = go.and_not(dark).and_not(roulette.and(u.ge(survive)));
        let carried = diffuse.select_v(weight / survive, weight);
        st.power = go.select_v(st.power * carried, st.power);
        st.origin = go.select_v(offset_origin(hits.point, hits.error, normal, wi), st.origin);
        st.direction = go.select_v(wi, st.direction);
        st.depth = st.depth.count_in(go);
        st.active = go.and_not(st.depth.ge(self.segments()));
    }
}
