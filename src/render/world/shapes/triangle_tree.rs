//! Many triangles found through a hierarchy (`Bvh`) whose leaves are
//! tested four triangles at a time (`TriangleLanes`' groups, a leaf's
//! triangles in its own groups): one pass of vector instructions a leaf,
//! from records laid out in the order the traversal meets them, where a
//! triangle at a time read each from wherever it lay in the scene's list.
//! What a ray finds is what `intersect_triangle` over the leaves'
//! triangles in the traversal's order finds, bit for bit.

use glam::Vec4;
use rayon::prelude::*;

use super::bvh::Bvh;
use super::triangle::{Group, TriangleLanes};
use super::triangle_boxes;
use crate::geometry::{Ray, RayShear, SurfaceHit, Triangle};

#[derive(Clone, Debug, Default)]
pub struct TriangleTree {
    /// Each leaf names its range of `lanes`' groups.
    bvh: Bvh,
    lanes: TriangleLanes,
}

impl TriangleTree {
    pub fn new(triangles: &[(Triangle, u32)]) -> Self {
        let mut bvh = Bvh::new(&triangle_boxes(triangles), 4);
        // Each leaf's groups made on any thread, then laid out in order
        let runs: Vec<Vec<Group>> =
            bvh.leaves().into_par_iter().map(|ids| TriangleLanes::groups_of(triangles, ids)).collect();
        let mut lanes = TriangleLanes::default();
        lanes.reserve_exact(runs.iter().map(Vec::len).sum());
        let mut runs = runs.into_iter();
        bvh.map_leaves(|_| lanes.push_groups(runs.next().unwrap_or_default()));
        TriangleTree { bvh, lanes }
    }

    /// The nearest of the triangles on the ray within (0, t_max): its
    /// index, its object and the hit, `intersect_triangle`'s (`triangle`
    /// gives a triangle by its index, for the rare ray only the scalar
    /// test decides).
    #[inline]
    pub fn nearest<'t>(
        &self,
        triangle: impl Fn(u32) -> &'t Triangle,
        ray: &Ray,
        t_max: f32,
    ) -> Option<(u32, u32, SurfaceHit)> {
        let shear = Self::shear_of(ray);
        let prefetch = |first, _| self.lanes.prefetch(first);
        self.bvh.nearest_leaf(ray, t_max, prefetch, |first, count, best_t| {
            let found = self.lanes.nearest_in(first..first + count, &triangle, ray, &shear, best_t);
            found.map(|found| (found.2.t, found))
        })
    }

    /// Whether any triangle but those `skip` names lies on the ray within
    /// (0, t_max).
    #[inline]
    pub fn any_hit<'t>(
        &self,
        triangle: impl Fn(u32) -> &'t Triangle,
        ray: &Ray,
        t_max: f32,
        skip: impl Fn(u32) -> bool,
    ) -> bool {
        let shear = Self::shear_of(ray);
        (self.bvh).any_leaf(ray, t_max, |first, count| {
            self.lanes.any_in(first..first + count, &triangle, ray, &shear, t_max, &skip)
        })
    }

    #[inline(always)]
    fn shear_of(ray: &Ray) -> RayShear<Vec4> {
        RayShear::of_one_ray(ray.origin, ray.direction)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::geometry::intersect_triangle;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// A closed mesh (a rippled sphere of quads, so rays cross shared edges
    /// and vertices), a grid of axis-aligned quads (exact zeros in the edge
    /// functions), a few long slivers and degenerate triangles; objects
    /// numbered apart from the triangles.
    fn scene(s: &mut Sampler) -> Vec<(Triangle, u32)> {
        let rings = 24;
        let point = |i: u32, j: u32| {
            let (theta, phi) =
                (std::f32::consts::PI * i as f32 / rings as f32, std::f32::consts::PI * j as f32 / rings as f32);
            let r = 1.0 + 0.1 * (7.0 * theta).sin() * (5.0 * phi).cos();
            Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()) * r
        };
        let mut out = Vec::new();
        for i in 0..rings {
            for j in 0..2 * rings {
                let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
                out.push((Triangle::new(a, c, b), 1));
                out.push((Triangle::new(a, d, c), 1));
            }
        }
        for x in 0..8 {
            for y in 0..8 {
                let p = Vec3::new(x as f32 - 4.0, y as f32 - 4.0, 2.0);
                out.push((Triangle::new(p, p + Vec3::X, p + Vec3::Y), 2));
                out.push((Triangle::new(p + Vec3::X, p + Vec3::ONE.with_z(0.0), p + Vec3::Y), 2));
            }
        }
        for k in 0..40 {
            let a = uniform_sphere(s.next_2d()) * 3.0;
            let far = if k % 2 == 0 { -a } else { a };
            out.push((Triangle::new(a, far, a + Vec3::splat(0.05)), 3 + k % 3));
        }
        out.push((Triangle::new(Vec3::ZERO, Vec3::ONE, Vec3::ONE), 9));
        out
    }

    /// The tree finds what testing every triangle finds: a hit where there
    /// is one, and, where it names the same triangle at the same t, the
    /// same hit bit for bit and the triangle's object. (Two triangles met
    /// at about one t, at an edge or crossing, may be tested in either
    /// order, and the first may leave the second's cull unsure of it: then
    /// the nearest t may differ by rounding.) Any hit exactly where there
    /// is one, with a skipped triangle too.
    #[test]
    fn finds_what_testing_every_triangle_finds() {
        let mut s = Sampler::new(0, 0, 61);
        let list = scene(&mut s);
        let tree = TriangleTree::new(&list);
        let triangle = |i: u32| &list[i as usize].0;
        let (mut hits, mut misses, mut same) = (0, 0, 0);
        for k in 0..20_000 {
            let origin = uniform_sphere(s.next_2d()) * (1.5 + 4.0 * s.next_f32());
            let target = match k % 3 {
                // A vertex: rays through shared edges and corners
                0 => list[k % list.len()].0.vertices[k % 3],
                1 => Vec3::new((k % 9) as f32 - 4.0, (k / 9 % 9) as f32 - 4.0, 2.0),
                _ => uniform_sphere(s.next_2d()) * 1.2 * s.next_f32(),
            };
            let ray = Ray::new(origin, (target - origin).normalize());
            let t_max = if k % 5 == 0 { 2.5 } else { f32::INFINITY };
            let mut expected: Option<(u32, SurfaceHit)> = None;
            for (i, (t, _)) in list.iter().enumerate() {
                if let Some(hit) = intersect_triangle(&ray, t, expected.map_or(t_max, |e| e.1.t)) {
                    expected = Some((i as u32, hit));
                }
            }
            let got = tree.nearest(triangle, &ray, t_max);
            assert_eq!(got.is_some(), expected.is_some(), "ray {ray:?}");
            if let (Some((i, object, a)), Some((j, b))) = (got, expected) {
                assert_eq!(object, list[i as usize].1);
                assert!((a.t - b.t).abs() <= 1e-5 * b.t, "ray {ray:?}: {} against {}", a.t, b.t);
                if (i, a.t) == (j, b.t) {
                    assert_eq!((a.point, a.normal, a.error), (b.point, b.normal, b.error));
                    same += 1;
                }
            }
            assert_eq!(tree.any_hit(triangle, &ray, t_max, |_| false), expected.is_some());
            if let Some((j, _)) = expected {
                let others = (list.iter().enumerate())
                    .any(|(i, (t, _))| i as u32 != j && intersect_triangle(&ray, t, t_max).is_some());
                assert_eq!(tree.any_hit(triangle, &ray, t_max, |i| i == j), others);
            }
            hits += expected.is_some() as u32;
            misses += expected.is_none() as u32;
        }
        assert!(hits > 5000 && misses > 2000 && same > hits / 2, "{hits} hits, {misses} misses, {same} same");
    }
}
