//! Spheres tested four at a time: the same cancellation-free form as
//! `geometry::sphere`, written over SIMD lanes (glam's `Vec4` is SSE on
//! x86-64), so a ray pays a few vector instructions per group of four.

use glam::{BVec4A, Vec3, Vec4};

use crate::geometry::real::V3;
use crate::geometry::sphere::nearest_root;
use crate::geometry::Ray;

/// Lanes with no sphere: a centre at infinity gives NaN, and every
/// comparison with NaN fails, so they never hit.
const EMPTY: f32 = f32::INFINITY;

#[derive(Clone, Debug, Default)]
pub struct SphereLanes {
    center_x: Vec<Vec4>,
    center_y: Vec<Vec4>,
    center_z: Vec<Vec4>,
    radius2: Vec<Vec4>,
    /// Which sphere of the world each lane holds, in order.
    ids: Vec<u32>,
}

impl SphereLanes {
    /// Spheres `ids` of the world, with these centres and radii.
    pub fn new(centers: &[Vec3], radii: &[f32], ids: Vec<u32>) -> Self {
        let groups = centers.len().div_ceil(4);
        let lane = |i: usize, f: &dyn Fn(usize) -> f32| {
            Vec4::from_array([0, 1, 2, 3].map(|k| if i * 4 + k < centers.len() { f(i * 4 + k) } else { EMPTY }))
        };
        Self {
            center_x: (0..groups).map(|i| lane(i, &|j| centers[j].x)).collect(),
            center_y: (0..groups).map(|i| lane(i, &|j| centers[j].y)).collect(),
            center_z: (0..groups).map(|i| lane(i, &|j| centers[j].z)).collect(),
            radius2: (0..groups).map(|i| lane(i, &|j| radii[j] * radii[j])).collect(),
            ids,
        }
    }

    /// The world's index of the sphere in lane `i`.
    #[inline]
    pub fn id(&self, i: usize) -> u32 {
        self.ids[i]
    }

    pub fn len(&self) -> usize {
        self.ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Per lane of one group: the nearest root in (0, t_max), infinity where
    /// there is none, and whether it is the near root.
    #[inline(always)]
    fn group(cx: Vec4, cy: Vec4, cz: Vec4, r2: Vec4, ray: &Ray, t_max: Vec4) -> (Vec4, BVec4A) {
        let (o, d) = (ray.origin, ray.direction);
        let f = V3::new(Vec4::splat(o.x) - cx, Vec4::splat(o.y) - cy, Vec4::splat(o.z) - cz);
        let (t, hit, near) = nearest_root(f, V3::splat(d), r2, t_max);
        (Vec4::select(hit, t, Vec4::INFINITY), hit & near)
    }

    /// The groups' lanes side by side (zipped: no bounds checks in the loop).
    #[inline(always)]
    fn groups(&self) -> impl Iterator<Item = (Vec4, Vec4, Vec4, Vec4)> + '_ {
        self.center_x
            .iter()
            .zip(&self.center_y)
            .zip(&self.center_z)
            .zip(&self.radius2)
            .map(|(((x, y), z), r)| (*x, *y, *z, *r))
    }

    /// Nearest hit in (0, t_max): (sphere index, t, near root).
    #[inline]
    pub fn nearest(&self, ray: &Ray, t_max: f32) -> Option<(usize, f32, bool)> {
        let mut best = t_max;
        let mut found = None;
        for (g, (cx, cy, cz, r2)) in self.groups().enumerate() {
            let (t, near) = Self::group(cx, cy, cz, r2, ray, Vec4::splat(best));
            let closest = t.min_element();
            if closest < best {
                // The lane holding the minimum, without a loop over lanes
                let lane = t.cmpeq(Vec4::splat(closest)).bitmask().trailing_zeros() as usize;
                best = closest;
                found = Some((g * 4 + lane, closest, near.bitmask() & (1 << lane) != 0));
            }
        }
        found
    }

    /// Whether any sphere lies on the ray in (0, t_max).
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        let limit = Vec4::splat(t_max);
        self.groups().any(|(cx, cy, cz, r2)| Self::group(cx, cy, cz, r2, ray, limit).0.cmplt(limit).any())
    }

    /// `any_hit` but for the world's sphere `except`.
    #[inline]
    pub fn any_hit_except(&self, ray: &Ray, t_max: f32, except: Option<u32>) -> bool {
        let Some(skip) = except.and_then(|id| self.ids.iter().position(|&i| i == id)) else {
            return self.any_hit(ray, t_max);
        };
        let limit = Vec4::splat(t_max);
        self.groups().enumerate().any(|(g, (cx, cy, cz, r2))| {
            let hits = Self::group(cx, cy, cz, r2, ray, limit).0.cmplt(limit).bitmask();
            let skipped = if skip / 4 == g { 1 << (skip % 4) } else { 0 };
            hits & !skipped != 0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sphere_t;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// Four-wide lanes agree with the scalar test, sphere by sphere.
    #[test]
    fn lanes_match_the_scalar_intersection() {
        let mut s = Sampler::new(0, 0, 99);
        for count in [1usize, 3, 4, 5, 9, 13] {
            let centers: Vec<Vec3> = (0..count).map(|_| uniform_sphere(s.next_2d()) * 5.0).collect();
            let radii: Vec<f32> = (0..count).map(|_| 0.2 + s.next_f32()).collect();
            let lanes = SphereLanes::new(&centers, &radii, (0..count as u32).collect());
            for _ in 0..2000 {
                let ray = Ray::new(uniform_sphere(s.next_2d()) * 8.0 * s.next_f32(), uniform_sphere(s.next_2d()));
                let t_max = if s.next_f32() < 0.3 { 4.0 } else { f32::INFINITY };
                let mut expected: Option<(usize, f32, bool)> = None;
                for i in 0..count {
                    if let Some((t, near)) = sphere_t(&ray, centers[i], radii[i], expected.map_or(t_max, |e| e.1)) {
                        expected = Some((i, t, near));
                    }
                }
                assert_eq!(lanes.nearest(&ray, t_max), expected);
                assert_eq!(lanes.any_hit(&ray, t_max), expected.is_some());
                // Without one sphere: whether any other lies on the ray
                let except = s.next_u64() as usize % count;
                let others = (0..count).any(|i| i != except && sphere_t(&ray, centers[i], radii[i], t_max).is_some());
                assert_eq!(lanes.any_hit_except(&ray, t_max, Some(except as u32)), others);
            }
        }
    }
}
