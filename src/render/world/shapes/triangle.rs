//! Triangles tested four at a time against one ray: the watertight test of
//! `geometry::triangle`, the same generic code over glam's `Vec4` (SSE on
//! x86-64), so a ray pays one pass of vector instructions per group of four
//! instead of four scalar tests. What the scalar test decides, hit or miss,
//! t and point, the lanes decide bit for bit: the arithmetic is the same
//! operation for operation, the rare ray whose edge function is exactly
//! zero (redone in f64 there) is handed to the scalar test, and hits are
//! taken in the scalar loop's order.
//!
//! A triangle light is sampled uniformly over its area.

use glam::{BVec4A, DVec3, Vec2, Vec3, Vec4};

use super::bvh::prefetch_lines;
use super::{solid_angle_pdf, AreaEmitter};
use crate::geometry::real::{Real, V3};
use crate::geometry::{
    beyond, edges_of, triangle_hit_of, watertight_finish_of, watertight_range_of, Crossing, CullPlane, RayShear,
};
use crate::geometry::{gamma, intersect_triangle, Ray, SurfaceHit, Triangle};
use crate::render::world::sampling::uniform_triangle;

/// Four triangles, lane by lane: first what the cull reads (planes and
/// edges, `geometry::cull`) and the triangles' names, four cache lines;
/// then what a hit reads, a line of objects and normals, and the vertices
/// the watertight test reads where the cull is not sure.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct Group {
    normal: V3<Vec4>,
    offset: Vec4,
    scale: Vec4,
    edges: [[Vec4; 3]; 3],
    /// The world's index of each lane's triangle.
    ids: [u32; 4],
    /// A bit a lane: where its plane drops x (keeps y, z), where it drops
    /// z (keeps x, y), and whether it holds a triangle (the last group of
    /// a run may be part empty): bits 0–3, 4–7, 8–11.
    lanes: u32,
    /// The fifth line: each triangle's normal (its plane's is its run's
    /// first triangle's), and its object.
    normals: V3<Vec4>,
    objects: [u32; 4],
    vertices: [V3<Vec4>; 3],
}

impl Group {
    /// The lanes whose bit `shift`…`shift + 3` of `lanes` is set.
    #[inline(always)]
    fn mask(&self, shift: u32) -> BVec4A {
        let bits = self.lanes >> shift;
        BVec4A::new(bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0)
    }

    #[inline(always)]
    fn full(&self) -> u32 {
        (self.lanes >> 8) & 0xf
    }

    /// Lane `k`'s triangle's plane, as `hit_point` reads it.
    #[inline(always)]
    fn plane(&self, k: usize) -> CullPlane {
        let normal = Vec3::new(self.normal.x[k], self.normal.y[k], self.normal.z[k]);
        CullPlane { normal, offset: self.offset[k], scale: self.scale[k], drop: 0 }
    }

    #[inline(always)]
    fn triangle_normal(&self, k: usize) -> Vec3 {
        Vec3::new(self.normals.x[k], self.normals.y[k], self.normals.z[k])
    }
}

/// What one group's lanes found for a ray within (0, t_max).
struct Verdict {
    /// Lanes hit within (0, t_max), by the f32 test.
    hit: u32,
    /// Lanes whose crossing lies inside by more than the cull's slack
    /// (`Crossing::test`): a shadow ray there is blocked, and the crossing
    /// is the hit.
    sure: u32,
    /// Where the ray crosses each lane's plane, and the slack.
    crossing: Crossing<Vec4>,
    /// Lanes the cull lets through whose edge functions met an exact zero:
    /// the scalar test decides them (in f64).
    scalar: u32,
    t: Vec4,
    t_scaled: Vec4,
    det: Vec4,
    barycentrics: [Vec4; 3],
}

#[derive(Clone, Debug, Default)]
pub struct TriangleLanes {
    groups: Vec<Group>,
}

impl TriangleLanes {
    pub fn new(triangles: &[(Triangle, u32)]) -> Self {
        let mut lanes = TriangleLanes::default();
        let ids: Vec<u32> = (0..triangles.len() as u32).collect();
        lanes.push_run(triangles, &ids);
        lanes
    }

    /// Groups for the triangles `ids` names after those already held, in
    /// their order (degenerate triangles, which nothing hits, left out):
    /// the range of groups they take, as (first, count).
    pub fn push_run(&mut self, triangles: &[(Triangle, u32)], ids: &[u32]) -> (u32, u32) {
        self.push_groups(Self::groups_of(triangles, ids))
    }

    /// `groups` after those already held: the range they take.
    pub fn push_groups(&mut self, groups: Vec<Group>) -> (u32, u32) {
        let first = self.groups.len() as u32;
        self.groups.extend(groups);
        (first, self.groups.len() as u32 - first)
    }

    /// Room for `more` groups, asked for at once.
    pub fn reserve_exact(&mut self, more: usize) {
        self.groups.reserve_exact(more);
    }

    /// The groups of the triangles `ids` names, in their order, the
    /// degenerate ones left out (`push_run`'s).
    pub fn groups_of(triangles: &[(Triangle, u32)], ids: &[u32]) -> Vec<Group> {
        let kept: Vec<u32> = ids.iter().copied().filter(|&i| !triangles[i as usize].0.is_degenerate()).collect();
        let group = |chunk: &[u32]| {
            // Empty lanes copy the last triangle and are masked off
            let id = |k: usize| chunk[k.min(chunk.len() - 1)];
            let lane = |k: usize| &triangles[id(k) as usize].0;
            let vec = |f: &dyn Fn(&Triangle) -> f32| Vec4::from_array([0, 1, 2, 3].map(|k| f(lane(k))));
            let point = |f: &dyn Fn(&Triangle) -> Vec3| V3::new(vec(&|t| f(t).x), vec(&|t| f(t).y), vec(&|t| f(t).z));
            let drops = |axis: usize| (0..4).filter(|&k| lane(k).cull.plane.drop == axis).map(|k| 1 << k).sum::<u32>();
            let edge = |e: usize, i: usize| vec(&|t| t.cull.edges.0[e][i]);
            Group {
                normal: point(&|t| t.cull.plane.normal),
                offset: vec(&|t| t.cull.plane.offset),
                scale: vec(&|t| t.cull.plane.scale),
                edges: [0, 1, 2].map(|e| [edge(e, 0), edge(e, 1), edge(e, 2)]),
                ids: [0, 1, 2, 3].map(id),
                objects: [0, 1, 2, 3].map(|k| triangles[id(k) as usize].1),
                lanes: drops(0) | drops(2) << 4 | ((1 << chunk.len()) - 1) << 8,
                normals: point(&|t| t.normal),
                vertices: [point(&|t| t.vertices[0]), point(&|t| t.vertices[1]), point(&|t| t.vertices[2])],
            }
        };
        kept.chunks(4).map(group).collect()
    }

    /// Asks the memory for what the cull and a hit read of group `g` (all
    /// but the vertices).
    #[inline(always)]
    pub fn prefetch(&self, g: u32) {
        if let Some(group) = self.groups.get(g as usize) {
            prefetch_lines(group, 5);
        }
    }

    /// One group against `ray` within (0, t_max); `None` where the cull
    /// turns the ray away in every lane (most groups, for most rays). The
    /// watertight test runs only where the cull lets a lane through but is
    /// not sure of it, so a group whose lanes it settles reads none of its
    /// vertices.
    #[inline(always)]
    fn verdict(group: &Group, ray: &Ray, shear: &RayShear<Vec4>, t_max: f32) -> Option<Verdict> {
        let (origin, direction) = (V3::<Vec4>::splat(ray.origin), V3::<Vec4>::splat(ray.direction));
        let limit = Vec4::splat(t_max);
        let (t, point, slack) = Crossing::point_of(origin, direction, group.normal, group.offset, group.scale);
        let u = Vec4::select(group.mask(0), point.y, point.x);
        let v = Vec4::select(group.mask(4), point.y, point.z);
        let crossing = Crossing { t, u, v, slack };
        let (turned_away, sure) = crossing.test(&group.edges, limit);
        let reach = !turned_away.bitmask() & group.full();
        if reach == 0 {
            return None;
        }
        let sure = sure.bitmask() & reach;
        let mut verdict = Verdict {
            hit: 0,
            sure,
            crossing,
            scalar: 0,
            t: Vec4::ZERO,
            t_scaled: Vec4::ZERO,
            det: Vec4::ZERO,
            barycentrics: [Vec4::ZERO; 3],
        };
        if reach == sure {
            return Some(verdict);
        }
        let (sheared, sz) = shear.vertices(group.vertices);
        let edges = edges_of(sheared);
        let zero = Vec4::ZERO;
        let on_edge: BVec4A = edges[0].cmpeq(zero) | edges[1].cmpeq(zero) | edges[2].cmpeq(zero);
        let scalar = on_edge.bitmask() & reach & !sure;
        let range = watertight_range_of(sheared, edges, sz, limit);
        let within = reach & !sure & !range.missed.bitmask() & !scalar;
        if within == 0 && scalar == 0 && sure == 0 {
            return None;
        }
        let (t, hit, barycentrics) = watertight_finish_of(sheared, edges, range);
        (verdict.hit, verdict.scalar, verdict.t, verdict.barycentrics) =
            (hit.bitmask() & within, scalar, t, barycentrics);
        (verdict.t_scaled, verdict.det) = (range.t_scaled, range.det);
        Some(verdict)
    }

    /// Nearest hit in (0, t_max): (the world's triangle index, its
    /// object, the hit), exactly what `intersect_triangle` over the
    /// triangles in order finds.
    #[inline]
    pub fn nearest(&self, triangles: &[(Triangle, u32)], ray: &Ray, t_max: f32) -> Option<(u32, u32, SurfaceHit)> {
        let shear = RayShear::of_one_ray(ray.origin, ray.direction);
        self.nearest_in(0..self.groups.len() as u32, |i| &triangles[i as usize].0, ray, &shear, t_max)
    }

    /// The nearest hit in (0, t_max) among the groups `range` (`shear` the
    /// ray's, `triangle` each triangle by its index, for the rare ray the
    /// scalar test decides), as `nearest`.
    #[inline(always)]
    pub fn nearest_in<'t>(
        &self,
        range: std::ops::Range<u32>,
        triangle: impl Fn(u32) -> &'t Triangle,
        ray: &Ray,
        shear: &RayShear<Vec4>,
        t_max: f32,
    ) -> Option<(u32, u32, SurfaceHit)> {
        let mut best_t = t_max;
        let mut found = None;
        for group in &self.groups[range.start as usize..range.end as usize] {
            let Some(verdict) = Self::verdict(group, ray, shear, best_t) else { continue };
            let (mut lanes, mut narrowed) = (verdict.hit | verdict.scalar | verdict.sure, false);
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let (id, object) = (group.ids[lane], group.objects[lane]);
                let (crossing_t, slack) = (verdict.crossing.t[lane], verdict.crossing.slack[lane]);
                let sure = verdict.sure & (1 << lane) != 0;
                // Sure against the group's t_max, and still against a nearer
                // one: the crossing is the hit, as `intersect_triangle` takes it
                if sure && (!narrowed || crossing_t + slack < best_t) {
                    let (point, error) =
                        group.plane(lane).hit_point(ray.origin.into(), ray.direction.into(), crossing_t);
                    let normal = group.triangle_normal(lane);
                    (best_t, narrowed) = (crossing_t, true);
                    found = Some((id, object, SurfaceHit { t: crossing_t, point: point.into(), normal, error }));
                    continue;
                }
                // No longer sure against a nearer hit, or on an edge: what
                // the scalar loop does there
                if sure || verdict.scalar & (1 << lane) != 0 {
                    if let Some(hit) = intersect_triangle(ray, triangle(id), best_t) {
                        (best_t, narrowed) = (hit.t, true);
                        found = Some((id, object, hit));
                    }
                    continue;
                }
                if verdict.hit & (1 << lane) == 0 {
                    continue;
                }
                // An earlier lane of this group may have brought t_max
                // nearer: the scalar loop would test both cull and hit
                // against it
                if narrowed {
                    let (t_scaled, det) = (verdict.t_scaled[lane], verdict.det[lane]);
                    let bound = best_t * det;
                    if beyond(crossing_t, slack, best_t)
                        || (det < 0.0 && t_scaled < bound)
                        || (det > 0.0 && t_scaled > bound)
                    {
                        continue;
                    }
                }
                let b = verdict.barycentrics.map(|b| b[lane]);
                let vertices = group.vertices.map(|v| V3::new(v.x[lane], v.y[lane], v.z[lane]));
                let (point, error) = triangle_hit_of(vertices, b);
                (best_t, narrowed) = (verdict.t[lane], true);
                let normal = group.triangle_normal(lane);
                found = Some((id, object, SurfaceHit { t: best_t, point: point.into(), normal, error }));
            }
        }
        found
    }

    /// Whether any triangle but those `skip` names lies on the ray in
    /// (0, t_max).
    #[inline]
    pub fn any_hit(&self, triangles: &[(Triangle, u32)], ray: &Ray, t_max: f32, skip: impl Fn(u32) -> bool) -> bool {
        let shear = RayShear::of_one_ray(ray.origin, ray.direction);
        self.any_in(0..self.groups.len() as u32, |i| &triangles[i as usize].0, ray, &shear, t_max, skip)
    }

    /// Whether any triangle of the groups `range` but those `skip` names
    /// lies on the ray in (0, t_max), `shear` the ray's.
    #[inline(always)]
    pub fn any_in<'t>(
        &self,
        range: std::ops::Range<u32>,
        triangle: impl Fn(u32) -> &'t Triangle,
        ray: &Ray,
        shear: &RayShear<Vec4>,
        t_max: f32,
        skip: impl Fn(u32) -> bool,
    ) -> bool {
        self.groups[range.start as usize..range.end as usize].iter().any(|group| {
            let Some(verdict) = Self::verdict(group, ray, shear, t_max) else { return false };
            let mut lanes = verdict.hit | verdict.sure | verdict.scalar;
            while lanes != 0 {
                let lane = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let id = group.ids[lane];
                if skip(id) {
                    continue;
                }
                if (verdict.hit | verdict.sure) & (1 << lane) != 0
                    || intersect_triangle(ray, triangle(id), t_max).is_some()
                {
                    return true;
                }
            }
            false
        })
    }
}

/// The point of barycentrics (b0, b1, 1 − b0 − b1) on a triangle, for one
/// point or several.
#[inline(always)]
pub fn triangle_point_of<R: Real>([a, b, c]: [V3<R>; 3], b0: R, b1: R) -> V3<R> {
    a * b0 + b * b1 + c * (R::splat(1.0) - b0 - b1)
}

impl AreaEmitter for Triangle {
    fn area(&self) -> f32 {
        Triangle::area(self)
    }

    fn emits_at(&self, _point: Vec3) -> bool {
        true
    }

    #[inline]
    fn error(&self) -> f32 {
        let [a, b, c] = self.vertices;
        gamma(7) * (a.abs() + b.abs() + c.abs()).max_element()
    }

    fn uniform_point(&self, u: Vec2) -> (Vec3, Vec3) {
        let (b0, b1) = uniform_triangle(u);
        (triangle_point_of(self.vertices.map(V3::from), b0, b1).into(), self.normal)
    }

    #[inline]
    fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let (point, normal) = self.uniform_point(u);
        let pdf = solid_angle_pdf(p, point, normal, Triangle::area(self));
        (pdf > 0.0).then_some((point, normal, pdf))
    }

    #[inline]
    fn pdf_from(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        solid_angle_pdf(p, hit.point, self.normal, Triangle::area(self))
    }

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool) -> bool {
        self.vertices.iter().all(|v| holds(v.as_dvec3(), 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shear_of;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// Quads split in two and fans about a shared vertex (rays through
    /// shared edges and vertices, where the f64 fallback runs), and loose
    /// triangles, some degenerate.
    fn triangles(s: &mut Sampler, count: usize) -> Vec<(Triangle, u32)> {
        let mut out = Vec::new();
        let point = |s: &mut Sampler| (Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) - 0.5) * 6.0;
        while out.len() < count {
            let (a, b, c, d) = (point(s), point(s), point(s), point(s));
            match out.len() % 4 {
                0 => {
                    out.push(Triangle::new(a, b, c));
                    out.push(Triangle::new(a, c, a + (c - b)));
                }
                1 => out.push(Triangle::new(a, a, b)),
                2 => {
                    // Axis-aligned, through the origin's grid: edge functions of zero
                    let z = a.z.round();
                    let (p, q) = (Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z));
                    out.push(Triangle::new(p, q, Vec3::new(0.0, 1.0, z)));
                    out.push(Triangle::new(q, Vec3::new(1.0, 1.0, z), Vec3::new(0.0, 1.0, z)));
                }
                _ => out.push(Triangle::new(a, b, d)),
            }
        }
        out.truncate(count);
        out.into_iter().zip(0..).collect()
    }

    /// What the cull reads of a group, and the triangles' names, are its
    /// first four cache lines; what a hit reads, the fifth.
    #[test]
    fn a_group_reads_its_lines_in_order() {
        use std::mem::{align_of, offset_of, size_of};
        assert_eq!(align_of::<Group>(), 64);
        assert!(offset_of!(Group, ids) + 16 <= 256 && offset_of!(Group, lanes) + 4 <= 256);
        assert_eq!(offset_of!(Group, normals), 256);
        assert_eq!(offset_of!(Group, objects), 256 + size_of::<V3<Vec4>>());
        assert_eq!(offset_of!(Group, vertices), 320);
        assert_eq!(size_of::<Group>(), 512);
    }

    /// Nearest hits and shadow tests agree with the scalar loop bit for bit.
    #[test]
    fn lanes_match_the_scalar_test_triangle_by_triangle() {
        let mut s = Sampler::new(0, 0, 7);
        let (mut hits, mut on_edges) = (0, 0);
        for count in [1usize, 3, 4, 5, 8, 11] {
            let list = triangles(&mut s, count);
            let lanes = TriangleLanes::new(&list);
            for k in 0..4000 {
                let origin = uniform_sphere(s.next_2d()) * 8.0 * s.next_f32();
                // Every third ray aims at a vertex or a grid point, to land on edges
                let ray = match k % 4 {
                    0 => {
                        let target = list[k % count].0.vertices[k % 3];
                        Ray::new(origin, (target - origin).normalize())
                    }
                    // Down the z axis through the grid's corners and edges
                    1 => {
                        let (x, y) = ((k / 4 % 3) as f32 * 0.5, (k / 12 % 3) as f32 * 0.5);
                        Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z)
                    }
                    2 => Ray::new(origin, (Vec3::new((k % 2) as f32, 0.0, (k % 5) as f32 - 2.0) - origin).normalize()),
                    _ => Ray::new(origin, uniform_sphere(s.next_2d())),
                };
                let t_max = if s.next_f32() < 0.3 { 4.0 } else { f32::INFINITY };
                let mut expected: Option<(u32, SurfaceHit)> = None;
                for (i, (triangle, _)) in list.iter().enumerate() {
                    if let Some(hit) = intersect_triangle(&ray, triangle, expected.map_or(t_max, |e| e.1.t)) {
                        expected = Some((i as u32, hit));
                    }
                }
                let got = lanes.nearest(&list, &ray, t_max);
                assert_eq!(got.map(|g| g.0), expected.map(|e| e.0), "ray {ray:?}");
                assert_eq!(got.map(|g| g.1), expected.map(|e| list[e.0 as usize].1));
                if let (Some((_, _, a)), Some((_, b))) = (got, expected) {
                    hits += 1;
                    assert_eq!([a.t, a.error], [b.t, b.error]);
                    assert_eq!((a.point, a.normal), (b.point, b.normal));
                }
                let skipped = (k % count) as u32;
                let scalar_any = |skip: Option<u32>| {
                    (list.iter().enumerate())
                        .any(|(i, (t, _))| Some(i as u32) != skip && intersect_triangle(&ray, t, t_max).is_some())
                };
                assert_eq!(lanes.any_hit(&list, &ray, t_max, |_| false), scalar_any(None));
                assert_eq!(lanes.any_hit(&list, &ray, t_max, |id| id == skipped), scalar_any(Some(skipped)));
                let (origin, direction) = (V3::<f32>::from(ray.origin), V3::<f32>::from(ray.direction));
                on_edges += list
                    .iter()
                    .filter(|(t, _)| edges_of(shear_of(origin, direction, t.vertices.map(V3::from)).0).contains(&0.0))
                    .count();
            }
        }
        // The test saw hits, and rays whose edge functions were exactly zero
        assert!(hits > 2000, "{hits} hits");
        assert!(on_edges > 100, "{on_edges} rays on edges");
    }
}
