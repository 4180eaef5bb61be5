//! Shadow rays eight at a time: `World::blocked`, bit for bit, skipping
//! what a light sample lies on.

use super::hits::RunCrossing;
use super::{LaneWorld, Occluder};
use crate::geometry::plane_t_of;
use crate::geometry::sphere::nearest_root;
use crate::geometry::Ray;
use crate::render::world::lanes::{self, F8, LANES, M8, V8};
use crate::render::world::occluders::Shadow;

impl LaneWorld {
    /// Lanes whose segment (origin, unit direction, t_max) meets `sphere`.
    #[inline(always)]
    fn hits(sphere: &Occluder, origin: V8, direction: V8, t_max: F8) -> M8 {
        let f = origin - V8::splat(sphere.center);
        nearest_root(f, direction, F8::splat(sphere.radius2), t_max).1
    }

    /// Lanes of `mask` whose shadow ray (origin, unit direction, t_max) is
    /// blocked; paths inside every wall skip the walls, and each ray what
    /// `skips` says it ends on (`Occluders::blocks_shadow`).
    #[inline(always)]
    pub(crate) fn blocked(
        &self,
        mask: M8,
        inside_walls: M8,
        origin: V8,
        direction: V8,
        t_max: F8,
        skips: &Skips,
    ) -> M8 {
        let mut blocked = M8::NONE;
        // Plain loops: a closure here would not inherit AVX2
        for sphere in &self.others {
            let aimed_at = match (sphere.emitter, skips) {
                (None, _) => M8::NONE,
                // Every ray ends on it: none can meet it
                (Some(id), Skips::All { sphere, .. }) if *sphere == Some(id) => continue,
                (Some(_), Skips::All { .. }) => M8::NONE,
                (Some(id), Skips::Lanes { spheres, .. }) => M8::from_fn(|i| spheres[i] == Some(id)),
            };
            blocked = blocked.or(Self::hits(sphere, origin, direction, t_max).and_not(aimed_at));
        }
        let outside = mask.and_not(inside_walls);
        if outside.any() {
            for sphere in &self.walls {
                blocked = blocked.or(outside.and(Self::hits(sphere, origin, direction, t_max)));
            }
        }
        for plane in &self.planes {
            if plane.wall.is_none() || outside.any() {
                let (normal, offset) = (V8::splat(plane.normal), F8::splat(plane.offset));
                let hits = plane_t_of(origin, direction, normal, offset, t_max).1;
                blocked = blocked.or(if plane.wall.is_some() { outside.and(hits) } else { hits });
            }
        }
        // Triangles where the ray may reach them, but those in the plane of
        // the light triangle a ray ends on
        let mut crossing = RunCrossing::new();
        // Through the hierarchy, lane by lane, where there is one
        if let Some(tree) = &self.triangles.tree {
            for lane in mask.and_not(blocked).lanes() {
                let ray = Ray::new(origin.lane(lane), direction.lane(lane));
                let skip = match skips {
                    Skips::All { plane, .. } => *plane,
                    Skips::Lanes { planes, .. } => planes[lane],
                };
                let triangle = |i: u32| &self.triangles.list[i as usize].0;
                let aimed_at = |i: u32| skip == Some(self.triangle_planes[i as usize]);
                if tree.any_hit(triangle, &ray, t_max.lane(lane), aimed_at) {
                    blocked.set(lane, true);
                }
            }
        }
        let grouped = if self.triangles.tree.is_some() { &[][..] } else { &self.triangles.list[..] };
        for (j, ((triangle, _), plane)) in grouped.iter().zip(&self.triangle_planes).enumerate() {
            let aimed_at = match skips {
                Skips::All { plane: skip, .. } if *skip == Some(*plane) => continue,
                Skips::All { .. } => M8::NONE,
                Skips::Lanes { planes, .. } => M8::from_fn(|i| planes[i] == Some(*plane)),
            };
            let open = mask.and_not(blocked).and_not(aimed_at);
            let (near, surely) = Self::cull(&self.triangle_culls[j], &mut crossing, open, origin, direction, t_max);
            blocked = blocked.or(surely);
            let near = near.and_not(surely);
            if near.any() {
                let shear = crossing.shear(origin, direction);
                blocked = blocked.or(Self::triangle_hits(triangle, near, origin, direction, &shear, t_max).0);
            }
        }
        mask.and(blocked)
    }

    /// Which of `shadows` something blocks (`blocked[i]` says of
    /// `shadows[i]`): `World::blocked` of each, bit for bit, eight at a time
    /// where the CPU has AVX2.
    pub fn shadows_blocked(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU has AVX2: a `LaneWorld` is made only where it does.
        #[allow(unsafe_code)]
        unsafe {
            self.shadows_blocked_avx2(shadows, blocked)
        };
        #[cfg(not(target_arch = "x86_64"))]
        self.shadows_blocked_lanes(shadows, blocked);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn shadows_blocked_avx2(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        self.shadows_blocked_lanes(shadows, blocked);
    }

    #[inline(always)]
    fn shadows_blocked_lanes(&self, shadows: &[Shadow], blocked: &mut [bool]) {
        for (eight, out) in shadows.chunks(LANES).zip(blocked.chunks_mut(LANES)) {
            let n = eight.len();
            let mask = M8::from_bits((1 << n) - 1);
            let lane = |i: usize| &eight[i.min(n - 1)];
            let origin = V8::from_fn(|i| lane(i).ray.origin);
            let direction = V8::from_fn(|i| lane(i).ray.direction);
            let t_max = F8::from_fn(|i| lane(i).t_max);
            let held = M8::from_fn(|i| lane(i).held);
            let spheres = lanes::each(|i| lane(i).on_sphere);
            let planes = lanes::each(|i| lane(i).on_triangle.map(|t| self.triangle_planes[t as usize]));
            let hit = self.blocked(mask, held, origin, direction, t_max, &Skips::Lanes { spheres, planes }).bits();
            for (i, out) in out.iter_mut().enumerate() {
                *out = hit & 1 << i != 0;
            }
        }
    }
}

/// What shadow rays need not test (`Occluders::blocks_shadow`): the sphere
/// a light sample lies on, and the light plane of the triangle it lies on.
pub(crate) enum Skips {
    /// The same for every lane (path tracing toward a scene's one light).
    All {
        sphere: Option<u32>,
        plane: Option<u32>,
    },
    Lanes {
        spheres: [Option<u32>; LANES],
        planes: [Option<u32>; LANES],
    },
}
