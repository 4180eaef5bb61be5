//! The hit loop: the nearest hit of eight rays at a time, bit for bit
//! `World::intersect_held` — spheres (walls asked only where a held ray
//! leaves them), planes, and triangles behind a test of where the rays
//! cross their plane (`geometry::cull`).

use glam::Vec3;

use super::{LaneHits, LaneSurfaces, LaneWorld};
use crate::geometry::sphere::{nearest_root, wall_exit_hit};
use crate::geometry::{edges_of, ray_shear_of, triangle_hit_of, watertight_finish_of, watertight_range_of, RayShear};
use crate::geometry::{intersect_triangle, Ray, SurfaceHit, Triangle};
use crate::geometry::{plane_exit_of, plane_point_of, plane_t_of, Crossing, CullEdges, CullPlane};
use crate::render::world::lanes::{self, Index8, F8, LANES, M8, V8};
use crate::render::world::{Hit, World};

impl LaneWorld {
    /// The nearest hits of up to eight rays, each `held` or not as
    /// `World::intersect_held` takes it, still in the lanes (`hits_of`
    /// gives them lane by lane: that function's hits, bit for bit), and the
    /// rays' directions; for callers that go on lane by lane (photons,
    /// light and camera subpaths, `flying`). Fast only inlined into code
    /// built for AVX2.
    #[inline(always)]
    pub(crate) fn lane_hits(&self, rays: &[Option<(Ray, bool)>; LANES]) -> (LaneHits, V8) {
        let active = M8::from_fn(|i| rays[i].is_some());
        let held = M8::from_fn(|i| rays[i].is_some_and(|(_, held)| held));
        let ray = |i: usize| rays[i].map_or(Ray::new(Vec3::ZERO, Vec3::Z), |(ray, _)| ray);
        let origin = V8::from_fn(|i| ray(i).origin);
        let direction = V8::from_fn(|i| ray(i).direction);
        (self.nearest(active, held, origin, direction), direction)
    }

    /// `lane_hits`' hits lane by lane, as `World::intersect_held` gives them.
    #[inline(always)]
    pub(crate) fn hits_of(&self, world: &World, hits: &LaneHits) -> [Option<Hit>; LANES] {
        // Out of the registers first: the closure below does not inherit AVX2
        let found = hits.found.bits();
        let shape = hits.shape.to_array();
        let t = hits.t.to_array();
        let error = hits.error.to_array();
        let point = [hits.point.x.to_array(), hits.point.y.to_array(), hits.point.z.to_array()];
        let normal = [hits.normal.x.to_array(), hits.normal.y.to_array(), hits.normal.z.to_array()];
        lanes::each(|i| {
            (found & 1 << i != 0).then(|| {
                let object = self.surfaces.records[shape[i] as usize].object;
                let surface = SurfaceHit {
                    t: t[i],
                    point: Vec3::new(point[0][i], point[1][i], point[2][i]),
                    normal: Vec3::new(normal[0][i], normal[1][i], normal[2][i]),
                    error: error[i],
                };
                Hit { surface, object, material: world.objects[object as usize].material }
            })
        })
    }

    /// The nearest hits of the rays of `active` (`held` those inside every
    /// wall) and the surfaces there, for callers that bounce in the lanes
    /// (photons). Fast only inlined into code built for AVX2.
    #[inline(always)]
    pub(crate) fn hit_surfaces(&self, active: M8, held: M8, origin: V8, direction: V8) -> (LaneHits, LaneSurfaces<'_>) {
        let hits = self.nearest(active, held, origin, direction);
        let surfaces = LaneSurfaces::new(&self.surfaces, hits.shape, hits.found);
        (hits, surfaces)
    }

    /// The nearest hit of each ray of `active` (`held` those inside every
    /// wall): `World::intersect_held`, eight rays at a time, bit for bit.
    #[inline(always)]
    pub(crate) fn nearest(&self, active: M8, held: M8, origin: V8, direction: V8) -> LaneHits {
        // Spheres in index order, ties keeping the first (`SphereLanes::nearest`):
        // all of them for paths not held, all but the walls for held ones.
        // Usually every path is held: then the walls' near roots are never asked
        let every_held = !active.and_not(held).any();
        let mut t_hit = F8::splat(f32::INFINITY);
        // The index in a float lane, counted there too: one blend per sphere
        let mut index = F8::splat(0.0);
        // Of the sphere hit so far: whether by its near root, and the
        // discriminant (`sphere_hits` rebuilds the point from them)
        let (mut sphere_near, mut sphere_discriminant) = (M8::NONE, F8::splat(0.0));
        let spheres = if every_held { &self.inner_spheres } else { &self.spheres };
        for sphere in spheres {
            let f = origin - V8::splat(sphere.center);
            // No lane's line meets it: no root to solve (`roots`' discriminant)
            let b = f.dot(direction);
            let discriminant = F8::splat(sphere.radius2) - (f - direction * b).length_squared();
            if !discriminant.ge(F8::splat(0.0)).and(active).any() {
                continue;
            }
            let (t, closer, near) = nearest_root(f, direction, F8::splat(sphere.radius2), t_hit);
            let closer = if sphere.wall.is_some() { closer.and_not(held) } else { closer };
            t_hit = closer.select(t, t_hit);
            index = closer.select(F8::splat(sphere.shape), index);
            sphere_near = closer.select_mask(near, sphere_near);
            sphere_discriminant = closer.select(discriminant, sphere_discriminant);
        }
        // The walls' ways out for held paths, after every other sphere:
        // a tie with one goes to the other sphere, as in `World::intersect_held`
        if held.any() {
            self.wall_exits.leave(held, origin, direction, &mut t_hit, &mut index);
        }
        // Planes: in index order for paths not held (`World::intersect`);
        // for held ones the planes that are not walls, then the walls'
        // ways out (`World::intersect_held`)
        let first_plane = self.index.first_plane as f32;
        let mut k = F8::splat(first_plane);
        for plane in &self.planes {
            if plane.wall.is_none() || !every_held {
                let (normal, offset) = (V8::splat(plane.normal), F8::splat(plane.offset));
                let (t, hits) = plane_t_of(origin, direction, normal, offset, t_hit);
                let closer = if plane.wall.is_some() { hits.and_not(held) } else { hits };
                t_hit = closer.select(t, t_hit);
                index = closer.select(k, index);
            }
            k = k + 1.0;
        }
        if held.any() {
            let mut k = F8::splat(first_plane);
            for plane in &self.planes {
                if let Some((inward, offset)) = plane.wall {
                    let (t, exits) = plane_exit_of(origin, direction, V8::splat(inward), F8::splat(offset), t_hit);
                    let closer = exits.and(held);
                    t_hit = closer.select(t, t_hit);
                    index = closer.select(k, index);
                }
                k = k + 1.0;
            }
        }
        // Triangles last, as both do: the crossing where the cull is sure,
        // the watertight test in the other lanes it lets through
        let first_triangle = self.index.first_triangle as f32;
        let (mut triangle_point, mut triangle_normal, mut triangle_error) =
            (V8::splat(Vec3::ZERO), V8::splat(Vec3::Z), F8::splat(0.0));
        let mut crossing = RunCrossing::new();
        // Through the hierarchy, lane by lane, where there is one
        if let Some(tree) = &self.triangles.tree {
            for lane in active.lanes() {
                let ray = Ray::new(origin.lane(lane), direction.lane(lane));
                let triangle = |i: u32| &self.triangles.list[i as usize].0;
                if let Some((j, _, hit)) = tree.nearest(triangle, &ray, t_hit.lane(lane)) {
                    t_hit.set_lane(lane, hit.t);
                    index.set_lane(lane, first_triangle + j as f32);
                    triangle_point.set_lane(lane, hit.point);
                    triangle_normal.set_lane(lane, hit.normal);
                    triangle_error.set_lane(lane, hit.error);
                }
            }
        }
        let grouped = if self.triangles.tree.is_some() { &[][..] } else { &self.triangles.list[..] };
        for (j, (triangle, _)) in grouped.iter().enumerate() {
            let (near, sure) = Self::cull(&self.triangle_culls[j], &mut crossing, active, origin, direction, t_hit);
            if sure.any() {
                let (point, error) = triangle.cull.plane.hit_point(origin, direction, crossing.at.t);
                t_hit = sure.select(crossing.at.t, t_hit);
                index = sure.select(F8::splat(first_triangle + j as f32), index);
                triangle_point = sure.select_v(point, triangle_point);
                triangle_normal = sure.select_v(V8::splat(triangle.normal), triangle_normal);
                triangle_error = sure.select(error, triangle_error);
            }
            let near = near.and_not(sure);
            if !near.any() {
                continue;
            }
            let shear = crossing.shear(origin, direction);
            let (hits, t, point, error) = Self::triangle_hits(triangle, near, origin, direction, &shear, t_hit);
            if hits.any() {
                t_hit = hits.select(t, t_hit);
                index = hits.select(F8::splat(first_triangle + j as f32), index);
                triangle_point = hits.select_v(point, triangle_point);
                triangle_normal = hits.select_v(V8::splat(triangle.normal), triangle_normal);
                triangle_error = hits.select(error, triangle_error);
            }
        }
        let found = active.and(t_hit.lt(F8::splat(f32::INFINITY)));
        let shape = index.to_index();
        let on_sphere = found.and(index.lt(F8::splat(first_plane)));
        let on_plane = found.and_not(on_sphere).and(index.lt(F8::splat(first_triangle)));

        let (mut point, mut normal, mut error) = (V8::splat(Vec3::ZERO), V8::splat(Vec3::Z), F8::splat(0.0));
        if on_sphere.any() {
            let roots = (sphere_near, sphere_discriminant);
            self.sphere_hits(
                on_sphere,
                held,
                shape,
                roots,
                origin,
                direction,
                t_hit,
                &mut point,
                &mut normal,
                &mut error,
            );
        }
        if on_plane.any() {
            let plane_normal = self.plane_normals.get(shape);
            let offset = self.plane_offsets.get(shape);
            let (p, e) = plane_point_of(origin, direction, plane_normal, offset, t_hit);
            point = on_plane.select_v(p, point);
            normal = on_plane.select_v(plane_normal, normal);
            error = on_plane.select(e, error);
        }
        let on_triangle = found.and_not(index.lt(F8::splat(first_triangle)));
        if on_triangle.any() {
            point = on_triangle.select_v(triangle_point, point);
            normal = on_triangle.select_v(triangle_normal, normal);
            error = on_triangle.select(triangle_error, error);
        }
        LaneHits { found, t: t_hit, shape, point, normal, error }
    }

    /// The hits of lanes `on_sphere` (`shape` their sphere's index), rebuilt
    /// from the closest approach as `sphere_hit` does, given whether the
    /// search took the near root and the discriminant (`roots`); a wall
    /// holding the path is left where `wall_exit` found it.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sphere_hits(
        &self,
        on_sphere: M8,
        held: M8,
        shape: Index8,
        (near, discriminant): (M8, F8),
        origin: V8,
        direction: V8,
        t_hit: F8,
        point: &mut V8,
        normal: &mut V8,
        error: &mut F8,
    ) {
        let columns = &self.sphere_columns;
        let center = columns.center.get(shape);
        let radius = columns.radius.get(shape);
        let leaving = held.and(columns.wall.get(shape).ne(F8::splat(0.0))).and(on_sphere);
        if on_sphere.and_not(leaving).any() {
            let f = origin - center;
            let closest = f - direction * f.dot(direction);
            let half_chord = discriminant.max(F8::splat(0.0)).sqrt();
            let from_center = near.select_v(closest - direction * half_chord, closest + direction * half_chord);
            let length = from_center.length();
            let n = length.gt(F8::splat(0.0)).select_v(from_center / length, -direction);
            *point = on_sphere.select_v(center + n * radius, *point);
            *normal = on_sphere.select_v(n, *normal);
            *error = on_sphere.select(columns.error.get(shape), *error);
        }
        if leaving.any() {
            let slack = columns.wall_slack.get(shape);
            let (p, n, e) = wall_exit_hit(origin, direction, t_hit, center, slack);
            *point = leaving.select_v(p, *point);
            *normal = leaving.select_v(n, *normal);
            *error = leaving.select(e, *error);
        }
    }

    /// `intersect_triangle` for the lanes of `near` (those `cull`
    /// lets through): which hit, and their distance, point and error bound.
    /// Lanes on an edge, where the scalar code redoes the edge functions in
    /// f64, take the scalar code.
    #[inline(always)]
    pub(super) fn triangle_hits(
        triangle: &Triangle,
        near: M8,
        origin: V8,
        direction: V8,
        shear: &RayShear<F8>,
        t_max: F8,
    ) -> (M8, F8, V8, F8) {
        let [a, b, c] = triangle.vertices;
        let vertices = [V8::splat(a), V8::splat(b), V8::splat(c)];
        let (sheared, sz) = shear.vertices(vertices);
        let edges = edges_of(sheared);
        let zero = F8::splat(0.0);
        let on_edge = near.and(edges[0].eq(zero).or(edges[1].eq(zero)).or(edges[2].eq(zero)));
        let range = watertight_range_of(sheared, edges, sz, t_max);
        if !near.and_not(range.missed).or(on_edge).any() {
            return (M8::NONE, zero, V8::splat(Vec3::ZERO), zero);
        }
        let (mut t, hit, barycentrics) = watertight_finish_of(sheared, edges, range);
        let mut hits = near.and_not(on_edge).and(hit);
        let (mut point, mut error) = match hits.any() {
            true => triangle_hit_of(vertices, barycentrics),
            false => (V8::splat(Vec3::ZERO), zero),
        };
        for lane in on_edge.lanes() {
            let ray = Ray::new(origin.lane(lane), direction.lane(lane));
            if let Some(hit) = intersect_triangle(&ray, triangle, t_max.lane(lane)) {
                hits.set(lane, true);
                t.set_lane(lane, hit.t);
                point.set_lane(lane, hit.point);
                error.set_lane(lane, hit.error);
            }
        }
        (hits, t, point, error)
    }

    /// Lanes of `mask` whose ray may hit triangle `j` within (0, t_max),
    /// and those sure to (`Crossing::test`: `intersect_triangle`'s first
    /// test). `crossing` keeps where the rays cross the plane of the run
    /// the last triangle asked about.
    #[inline(always)]
    pub(super) fn cull(
        triangle: &LaneCull,
        crossing: &mut RunCrossing,
        mask: M8,
        origin: V8,
        direction: V8,
        t_max: F8,
    ) -> (M8, M8) {
        if !mask.any() || triangle.degenerate {
            return (M8::NONE, M8::NONE);
        }
        if crossing.run != triangle.run {
            crossing.run = triangle.run;
            crossing.at = Crossing::of(origin, direction, &triangle.plane);
        }
        let (turned_away, surely) = crossing.at.test(&triangle.edges.load(), t_max);
        (mask.and_not(turned_away), mask.and(surely))
    }
}

/// What `cull` reads of a triangle.
#[derive(Clone, Debug)]
pub(super) struct LaneCull {
    /// Its edges, each coefficient splat into eight lanes, read straight
    /// into the test rather than splat afresh for every batch of rays.
    edges: LaneEdges,
    plane: CullPlane,
    /// Which run of triangles in one plane it belongs to
    /// (`Triangle::share_planes`): a run's rays cross its plane once.
    run: u32,
    degenerate: bool,
}

/// A triangle's `CullEdges`, each coefficient in every lane.
#[derive(Clone, Debug)]
#[repr(align(32))]
struct LaneEdges([[[f32; LANES]; 3]; 3]);

impl LaneEdges {
    fn of(edges: &CullEdges) -> Self {
        LaneEdges(edges.0.map(|edge| edge.map(|c| [c; LANES])))
    }

    #[inline(always)]
    fn load(&self) -> [[F8; 3]; 3] {
        // Written out: `map`'s closures are left out of line, without AVX2
        let [[a0, b0, c0], [a1, b1, c1], [a2, b2, c2]] = &self.0;
        [
            [F8::load(a0), F8::load(b0), F8::load(c0)],
            [F8::load(a1), F8::load(b1), F8::load(c1)],
            [F8::load(a2), F8::load(b2), F8::load(c2)],
        ]
    }
}

/// Where eight rays cross the plane of a run of triangles, and their
/// shear for the watertight test once one needs it.
pub(super) struct RunCrossing {
    run: u32,
    at: Crossing<F8>,
    /// Worked out only once a batch the cull lets through needs it (a
    /// division and the axes' selects): a scene of no triangles, or rays
    /// the cull decides, never pay for it.
    shear: Option<RayShear<F8>>,
}

impl RunCrossing {
    /// Of no run yet.
    #[inline(always)]
    pub(super) fn new() -> Self {
        let zero = F8::splat(0.0);
        RunCrossing { run: u32::MAX, at: Crossing { t: zero, u: zero, v: zero, slack: zero }, shear: None }
    }

    /// The rays' shear, worked out the first time it is asked for.
    #[inline(always)]
    pub(super) fn shear(&mut self, origin: V8, direction: V8) -> RayShear<F8> {
        // A match, not `get_or_insert_with`: a closure would lose AVX2
        match self.shear {
            Some(shear) => shear,
            None => *self.shear.insert(ray_shear_of(origin, direction)),
        }
    }
}

/// What the cull reads of each triangle, its run of triangles in one plane
/// counted from 0 (`Triangle::share_planes` gave a run one plane).
pub(super) fn lane_culls(triangles: &[(Triangle, u32)]) -> Vec<LaneCull> {
    let mut run = 0;
    (0..triangles.len())
        .map(|j| {
            let triangle = &triangles[j].0;
            run += (j > 0 && triangle.cull.plane != triangles[j - 1].0.cull.plane) as u32;
            LaneCull {
                edges: LaneEdges::of(&triangle.cull.edges),
                plane: triangle.cull.plane,
                run,
                degenerate: triangle.is_degenerate(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shear_of;

    /// The lanes' triangle test (the crossing where the cull is sure, the
    /// watertight test in the other lanes it lets through) is
    /// `intersect_triangle`, bit for bit: on random rays, and on rays
    /// straight down onto a quad's edges and vertices, where edge functions
    /// are exactly zero and the scalar code redoes them in f64.
    #[test]
    fn triangle_hits_are_the_scalar_ones() {
        use crate::render::world::rng::Sampler;
        let quad =
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let triangles = [Triangle::new(quad[0], quad[1], quad[3]), Triangle::new(quad[1], quad[2], quad[3])];
        let mut rays = Vec::new();
        for i in 0..=16 {
            for j in 0..=16 {
                let at = Vec3::new(i as f32 / 16.0 - 0.25, j as f32 / 16.0 - 0.25, 1.0);
                rays.push((at, -Vec3::Z, if (i + j) % 3 == 0 { 0.5 } else { f32::INFINITY }));
            }
        }
        let mut rng = Sampler::new(0, 0, 7);
        while rays.len() % LANES != 0 || rays.len() < 800 {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
            let target = Vec3::new(rng.next_f32() * 1.4 - 0.2, rng.next_f32() * 1.4 - 0.2, 0.0);
            rays.push((origin, (target - origin).normalize(), 10.0));
        }
        let (mut on_edges, mut hits_seen, mut misses_seen, mut sure_seen) = (0, 0, 0, 0);
        for triangle in &triangles {
            for batch in rays.chunks(LANES) {
                let origin = V8::from_fn(|i| batch[i].0);
                let direction = V8::from_fn(|i| batch[i].1);
                let t_max = F8::from_fn(|i| batch[i].2);
                let crossing = Crossing::of(origin, direction, &triangle.cull.plane);
                let (turned_away, sure) = crossing.test(&triangle.cull.edges.splat(), t_max);
                let near = (!turned_away).and_not(sure);
                let shear = ray_shear_of(origin, direction);
                let (hits, t, point, error) =
                    LaneWorld::triangle_hits(triangle, near, origin, direction, &shear, t_max);
                let (sure_point, sure_error) = triangle.cull.plane.hit_point(origin, direction, crossing.t);
                let (hits, t) = (hits.or(sure), sure.select(crossing.t, t));
                let (point, error) = (sure.select_v(sure_point, point), sure.select(sure_error, error));
                sure_seen += sure.count();
                for (i, &(o, d, t_max)) in batch.iter().enumerate() {
                    let vertices = triangle.vertices.map(crate::geometry::real::V3::from);
                    on_edges += edges_of(shear_of(o.into(), d.into(), vertices).0).contains(&0.0) as u32;
                    let expected = intersect_triangle(&Ray::new(o, d), triangle, t_max);
                    assert_eq!(hits.test(i), expected.is_some(), "ray {o} {d}");
                    if let Some(hit) = expected {
                        hits_seen += 1;
                        assert_eq!(t.lane(i).to_bits(), hit.t.to_bits());
                        assert_eq!(point.lane(i).to_array().map(f32::to_bits), hit.point.to_array().map(f32::to_bits));
                        assert_eq!(error.lane(i).to_bits(), hit.error.to_bits());
                    } else {
                        misses_seen += 1;
                    }
                }
            }
        }
        assert!(on_edges > 50 && hits_seen > 300 && misses_seen > 300, "{on_edges} {hits_seen} {misses_seen}");
        assert!(sure_seen > 100 && hits_seen >= sure_seen + 10, "{sure_seen} of {hits_seen} hits by the crossing");
    }
}
