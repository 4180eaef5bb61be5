use glam::{DVec3, Vec3};

use super::cull::{Crossing, TriangleCull};
use super::real::{Mask, Real, V3};
use super::{gamma, Ray, SurfaceHit};

/// A triangle with its geometric normal precomputed; a degenerate one (zero
/// area) has a zero normal and is never hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub vertices: [Vec3; 3],
    pub normal: Vec3,
    /// Its plane and edges, for turning away rays that cross the plane
    /// elsewhere (`cull`).
    pub cull: TriangleCull,
    area: f32,
}

impl Triangle {
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        // Normal in f64 so thin but valid triangles far from the origin keep one
        let (a64, b64, c64) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let n = (b64 - a64).cross(c64 - a64);
        let length = n.length();
        let normal = if length > 0.0 && length.is_finite() { (n / length).as_vec3() } else { Vec3::ZERO };
        let area = (0.5 * length) as f32;
        let vertices = [a, b, c];
        let scale = vertices.iter().map(|v| v.abs().max_element()).fold(0.0, f32::max);
        let cull = TriangleCull::new(vertices, TriangleCull::plane_of(vertices, normal, scale));
        Self { vertices, normal, cull, area }
    }

    /// Planes shared along runs of coplanar triangles: each triangle in
    /// the plane of the first of its run (`holds_in_plane`), with the run's
    /// scale, so that the lanes cross each run's plane once for all of it.
    /// Runs, not groups: a scene's quads come as neighbours, and a run is
    /// found in one pass however many triangles there are.
    pub fn share_planes(triangles: &mut [&mut Triangle]) {
        let mut start = 0;
        while start < triangles.len() {
            let leader = *triangles[start];
            let mut end = start + 1;
            while end < triangles.len() && !leader.is_degenerate() && leader.holds_in_plane(triangles[end]) {
                end += 1;
            }
            let run = &mut triangles[start..end];
            let vertices = run.iter().flat_map(|t| t.vertices);
            let scale = vertices.map(|v| v.abs().max_element()).fold(0.0, f32::max);
            let plane = TriangleCull::plane_of(leader.vertices, leader.normal, scale);
            for triangle in run.iter_mut() {
                triangle.cull = TriangleCull::new(triangle.vertices, plane);
            }
            start = end;
        }
    }

    pub fn is_degenerate(&self) -> bool {
        self.normal == Vec3::ZERO
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    /// Whether `other` lies in this triangle's plane, to within rounding.
    pub fn holds_in_plane(&self, other: &Triangle) -> bool {
        let (normal, a) = (self.normal.as_dvec3(), self.vertices[0].as_dvec3());
        let scale = other.vertices.iter().chain(&self.vertices).map(|v| v.abs().max_element()).fold(0.0, f32::max);
        !self.is_degenerate()
            && other
                .vertices
                .iter()
                .all(|v| normal.dot(v.as_dvec3() - a).abs() <= 4.0 * f32::EPSILON as f64 * scale as f64)
    }
}

/// Watertight ray–triangle intersection (Woop, Benthin, Wald 2013, as in
/// pbrt-v4): shear the triangle into the ray's space so that rays through
/// shared edges and vertices hit exactly one side or both, never neither.
/// Rays that cross the plane away from the triangle are turned away first
/// (`cull`), and those that cross it well inside take the crossing as
/// their hit: the watertight test is for the rays near an edge.
#[inline]
pub fn intersect_triangle(ray: &Ray, triangle: &Triangle, t_max: f32) -> Option<SurfaceHit> {
    if triangle.is_degenerate() {
        return None;
    }
    let (origin, direction) = (ray.origin.into(), ray.direction.into());
    let crossing = Crossing::<f32>::of(origin, direction, &triangle.cull.plane);
    let (turned_away, sure) = crossing.test(&triangle.cull.edges.splat(), t_max);
    if turned_away {
        return None;
    }
    // Inside every edge and the segment by more than the slack: the
    // watertight test could only agree, and its t and point are no better
    if sure {
        let (point, error) = triangle.cull.plane.hit_point(origin, direction, crossing.t);
        return Some(SurfaceHit { t: crossing.t, point: point.into(), normal: triangle.normal, error });
    }
    watertight(ray, triangle, t_max)
}

#[inline]
fn watertight(ray: &Ray, triangle: &Triangle, t_max: f32) -> Option<SurfaceHit> {
    let vertices = triangle.vertices.map(V3::from);
    let (sheared, sz) = shear_of(ray.origin.into(), ray.direction.into(), vertices);
    let mut edges = edges_of(sheared);
    // On an edge, redone in f64 (where the f32 products cancelled to zero)
    if edges.contains(&0.0) {
        let [a, b, c] = sheared.map(|p| Vec3::from(p).as_dvec3());
        let edge = |u: DVec3, v: DVec3| (u.x * v.y - u.y * v.x) as f32;
        edges = [edge(b, c), edge(c, a), edge(a, b)];
    }
    let (t, hit, barycentrics) = watertight_hit_of(sheared, edges, sz, t_max);
    if !hit {
        return None;
    }
    let (point, error) = triangle_hit_of(vertices, barycentrics);
    Some(SurfaceHit { t, point: point.into(), normal: triangle.normal, error })
}

/// The watertight test's first step, for one ray or several: the vertices
/// translated to the ray's origin, permuted so that z is the largest axis
/// of its direction and sheared so that it points along +z (z not yet
/// scaled), and the scale `sz` for z.
#[inline(always)]
pub fn shear_of<R: Real>(origin: V3<R>, direction: V3<R>, vertices: [V3<R>; 3]) -> ([V3<R>; 3], R) {
    ray_shear_of(origin, direction).vertices(vertices)
}

/// The ray's part of `shear_of`, the same for every triangle it is tested
/// against: its direction's largest axis and the shear.
#[derive(Clone, Copy)]
pub struct RayShear<R: Real> {
    permutation: Permutation<R>,
    /// The origin, permuted.
    origin: V3<R>,
    sx: R,
    sy: R,
    sz: R,
}

/// Which axis becomes z.
#[derive(Clone, Copy)]
enum Permutation<R: Real> {
    /// Lane by lane: rays of their own.
    Lanes { y_largest: R::Mask, z_largest: R::Mask },
    /// One ray's in every lane (0, 1, 2: x, y or z largest): a reordering,
    /// not selects.
    Uniform(usize),
}

impl<R: Real> Permutation<R> {
    /// Permuting is a selection, so permuting a difference is the
    /// difference of the permuted (bit for bit). Functions, not closures: a
    /// closure is left out of line, without AVX2.
    #[inline(always)]
    fn apply(&self, v: V3<R>) -> V3<R> {
        match *self {
            Permutation::Lanes { y_largest, z_largest } => V3::new(
                R::select(z_largest, v.x, R::select(y_largest, v.z, v.y)),
                R::select(z_largest, v.y, R::select(y_largest, v.x, v.z)),
                R::select(z_largest, v.z, R::select(y_largest, v.y, v.x)),
            ),
            Permutation::Uniform(2) => v,
            Permutation::Uniform(1) => V3::new(v.z, v.x, v.y),
            Permutation::Uniform(_) => V3::new(v.y, v.z, v.x),
        }
    }
}

#[inline(always)]
pub fn ray_shear_of<R: Real>(origin: V3<R>, direction: V3<R>) -> RayShear<R> {
    let (y_largest, z_largest) = largest_axis_of(direction);
    RayShear::with(Permutation::Lanes { y_largest, z_largest }, origin, direction)
}

/// glam's `max_position` of |d| (the first largest), as selects: whether y
/// is larger than x, whether z is larger than both.
#[inline(always)]
fn largest_axis_of<R: Real>(direction: V3<R>) -> (R::Mask, R::Mask) {
    let a = direction.abs();
    let y_largest = a.y.gt(a.x);
    (y_largest, a.z.gt(R::select(y_largest, a.y, a.x)))
}

impl<R: Real> RayShear<R> {
    #[inline(always)]
    fn with(permutation: Permutation<R>, origin: V3<R>, direction: V3<R>) -> Self {
        let d = permutation.apply(direction);
        let sz = R::splat(1.0) / d.z;
        RayShear { permutation, origin: permutation.apply(origin), sx: -d.x * sz, sy: -d.y * sz, sz }
    }

    /// One ray's shear in every lane, to test it against several triangles
    /// side by side: the same numbers as `ray_shear_of` of the ray splat.
    #[inline(always)]
    pub fn of_one_ray(origin: Vec3, direction: Vec3) -> Self {
        let (y_largest, z_largest) = largest_axis_of::<f32>(direction.into());
        let one = RayShear::<f32>::with(Permutation::Lanes { y_largest, z_largest }, origin.into(), direction.into());
        let splat = |v: V3<f32>| V3::new(R::splat(v.x), R::splat(v.y), R::splat(v.z));
        RayShear {
            permutation: Permutation::Uniform(if z_largest { 2 } else { y_largest as usize }),
            origin: splat(one.origin),
            sx: R::splat(one.sx),
            sy: R::splat(one.sy),
            sz: R::splat(one.sz),
        }
    }

    /// A triangle's vertices in the ray's sheared space, and the scale of z.
    #[inline(always)]
    pub fn vertices(&self, [p0, p1, p2]: [V3<R>; 3]) -> ([V3<R>; 3], R) {
        ([self.vertex(p0), self.vertex(p1), self.vertex(p2)], self.sz)
    }

    #[inline(always)]
    fn vertex(&self, p: V3<R>) -> V3<R> {
        let p = self.permutation.apply(p) - self.origin;
        V3::new(p.x + self.sx * p.z, p.y + self.sy * p.z, p.z)
    }
}

/// The edge functions of the sheared vertices; where one is exactly zero
/// the scalar code redoes them in f64.
#[inline(always)]
pub fn edges_of<R: Real>([p0, p1, p2]: [V3<R>; 3]) -> [R; 3] {
    [p1.x * p2.y - p1.y * p2.x, p2.x * p0.y - p2.y * p0.x, p0.x * p1.y - p0.y * p1.x]
}

/// The watertight test's verdict from the sheared vertices and their edge
/// functions: (t, whether the ray hits within (δt, t_max), barycentrics).
#[inline(always)]
pub fn watertight_hit_of<R: Real>(sheared: [V3<R>; 3], edges: [R; 3], sz: R, t_max: R) -> (R, R::Mask, [R; 3]) {
    let range = watertight_range_of(sheared, edges, sz, t_max);
    watertight_finish_of(sheared, edges, range)
}

/// The watertight test's first half, what needs no division: whether the
/// edge functions agree in sign and the scaled distance lies within
/// (0, t_max). Lanes that fail it (`WatertightRange::missed`) miss.
#[inline(always)]
pub fn watertight_range_of<R: Real>(sheared: [V3<R>; 3], [e0, e1, e2]: [R; 3], sz: R, t_max: R) -> WatertightRange<R> {
    let zero = R::splat(0.0);
    let [p0, p1, p2] = sheared;
    // Inside when the edge functions do not differ in sign
    let negative = e0.lt(zero).or(e1.lt(zero)).or(e2.lt(zero));
    let positive = e0.gt(zero).or(e1.gt(zero)).or(e2.gt(zero));
    let det = e0 + e1 + e2;
    // Scaled distance, tested against the range before dividing
    let z = [p0.z * sz, p1.z * sz, p2.z * sz];
    let t_scaled = e0 * z[0] + e1 * z[1] + e2 * z[2];
    let bound = t_max * det;
    let behind_or_beyond = (det.lt(zero).and(t_scaled.ge(zero).or(t_scaled.lt(bound))))
        .or(det.gt(zero).and(t_scaled.le(zero).or(t_scaled.gt(bound))));
    let missed = negative.and(positive).or(det.eq(zero)).or(behind_or_beyond);
    WatertightRange { missed, det, t_scaled, z }
}

/// `watertight_range_of`'s findings: the lanes out of range or of the
/// triangle, and what the rest of the test reads.
#[derive(Clone, Copy)]
pub struct WatertightRange<R: Real> {
    pub missed: R::Mask,
    pub det: R,
    pub t_scaled: R,
    z: [R; 3],
}

/// The watertight test's second half: (t, hit, barycentrics), a hit only
/// within range and beyond the distance rounding could fake (pbrt's δt).
#[inline(always)]
pub fn watertight_finish_of<R: Real>(
    sheared: [V3<R>; 3],
    [e0, e1, e2]: [R; 3],
    range: WatertightRange<R>,
) -> (R, R::Mask, [R; 3]) {
    let [p0, p1, p2] = sheared;
    let WatertightRange { missed, det, t_scaled, z: [z0, z1, z2] } = range;
    let inv_det = R::splat(1.0) / det;
    let barycentrics = [e0 * inv_det, e1 * inv_det, e2 * inv_det];
    let t = t_scaled * inv_det;
    // Conservatively reject t too close to zero to be trusted (pbrt's δt)
    let max_zt = V3::new(z0, z1, z2).abs().max_element();
    let delta_z = max_zt * gamma(3);
    let max_xt = V3::new(p0.x, p1.x, p2.x).abs().max_element();
    let max_yt = V3::new(p0.y, p1.y, p2.y).abs().max_element();
    let delta_x = (max_xt + max_zt) * gamma(5);
    let delta_y = (max_yt + max_zt) * gamma(5);
    let delta_e = (max_xt * gamma(2) * max_yt + delta_y * max_xt + delta_x * max_yt) * 2.0;
    let max_e = V3::new(e0, e1, e2).abs().max_element();
    let delta_t = (max_e * gamma(3) * max_zt + delta_e * max_zt + delta_z * max_e) * 3.0 * inv_det.abs();
    let hit = t.is_finite().and_not(t.le(delta_t)).and_not(missed);
    (t, hit, barycentrics)
}

/// The point of a hit from its barycentrics, as a weighted sum of the
/// vertices, and its error bound.
#[inline(always)]
pub fn triangle_hit_of<R: Real>([p0, p1, p2]: [V3<R>; 3], [b0, b1, b2]: [R; 3]) -> (V3<R>, R) {
    let weighted = [p0 * b0, p1 * b1, p2 * b2];
    let point = weighted[0] + weighted[1] + weighted[2];
    let error = (weighted[0].abs() + weighted[1].abs() + weighted[2].abs()).max_element() * gamma(7);
    (point, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coplanar_triangles_far_from_the_origin() {
        let at = Vec3::new(1.0e4, -3.0e3, 2.0e4);
        let (u, v) = (Vec3::new(0.6, 0.8, 0.0), Vec3::new(0.0, 0.0, 1.0));
        let quad = [at, at + u, at + u + v, at + v];
        let a = Triangle::new(quad[0], quad[1], quad[2]);
        let b = Triangle::new(quad[0], quad[2], quad[3]);
        assert!(a.holds_in_plane(&b) && b.holds_in_plane(&a));
        assert!((a.area() - 0.5).abs() < 1e-3 && (b.area() - 0.5).abs() < 1e-3);
        // Lifted off the plane by 0.05 (25 ulps of 2e4): no longer in it
        let lifted = Triangle::new(quad[0], quad[2], quad[3] + u.cross(v) * 0.05);
        assert!(!a.holds_in_plane(&lifted));
    }

    #[test]
    fn hits_inside_and_misses_outside() {
        let tri = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        let hit = intersect_triangle(&Ray::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z), &tri, f32::INFINITY).unwrap();
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert_eq!(hit.normal, Vec3::Z);
        assert!(intersect_triangle(&Ray::new(Vec3::new(2.0, 0.0, 2.0), -Vec3::Z), &tri, f32::INFINITY).is_none());
        assert!(intersect_triangle(&Ray::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z), &tri, 1.0).is_none());
    }

    /// Uniform numbers in [0, 1) from xorshift64, seeded.
    fn uniform_stream(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The cull's verdict on `ray` and `tri`: (turned away, sure).
    fn cull(ray: &Ray, tri: &Triangle) -> (bool, bool) {
        let crossing = Crossing::<f32>::of(ray.origin.into(), ray.direction.into(), &tri.cull.plane);
        crossing.test(&tri.cull.edges.splat(), f32::INFINITY)
    }

    /// The cull in front of the watertight test never turns a hit into a
    /// miss: triangles at scales 1e-6 … 1e6, 100 of their sizes from the
    /// origin, seen from 1e-3 to 1e3 of their size away, rays aimed at
    /// vertices, edge points and interiors. It turns away rays sent the
    /// other way, and rays that cross the plane beside an edge (those not
    /// grazing it); a ray it calls sure, the watertight test hits, and its
    /// hit (the crossing) lies within its error bound of the triangle.
    #[test]
    fn the_cull_never_turns_away_a_hit() {
        let mut uniform = uniform_stream(0x2545_f491_4f6c_dd1d);
        let (mut hits, mut sure, mut away, mut away_turned, mut beside, mut beside_turned) = (0, 0, 0, 0, 0, 0);
        let mut worst = 0f64;
        for case in 0..40_000 {
            let scale = 10f32.powf(uniform() * 12.0 - 6.0);
            let mut point = || Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5) * 2.0;
            let offset = point() * scale * 100.0;
            let tri = Triangle::new(offset + point() * scale, offset + point() * scale, offset + point() * scale);
            // Vertices, edge midpoints and interior points
            let [a, b, c] = tri.vertices;
            let target = match case % 3 {
                0 => [a, b, c][case / 3 % 3],
                1 => (a + b) * 0.5,
                _ => a * 0.2 + b * 0.3 + c * 0.5,
            };
            let origin = target + point().normalize() * scale * 10f32.powf(uniform() * 6.0 - 3.0);
            let ray = Ray::new(origin, (target - origin).normalize());
            let (turned_away, surely) = cull(&ray, &tri);
            let hit = watertight(&ray, &tri, f32::INFINITY).is_some();
            if hit {
                hits += 1;
                assert!(!turned_away, "case {case}: a hit turned away by the cull of {tri:?}, ray {ray:?}");
            }
            if surely {
                sure += 1;
                assert!(hit, "case {case}: sure of a ray the watertight test misses, {tri:?}, ray {ray:?}");
                // Its hit is the crossing, off the triangle's exact plane
                // (f64) by no more than the bound a spawned ray clears
                let found = intersect_triangle(&ray, &tri, f32::INFINITY).expect("a sure hit");
                let [a64, b64, c64] = tri.vertices.map(|v| v.as_dvec3());
                let normal = (b64 - a64).cross(c64 - a64).normalize();
                let off_plane = normal.dot(found.point.as_dvec3() - a64).abs();
                assert!(
                    off_plane <= found.error as f64,
                    "case {case}: {off_plane} off the plane, bound {}",
                    found.error
                );
                worst = worst.max(off_plane / found.error as f64);
            }
            // Away from the triangle, for rays not grazing its plane from
            // within a few sizes of it (further off, or grazing, the slack
            // grows past the triangle's size)
            let (distance, cos) = ((origin - target).length(), ray.direction.dot(tri.normal).abs());
            if tri.is_degenerate() || distance < scale || distance > scale * 10.0 || cos < 0.2 {
                continue;
            }
            // The opposite way: the plane lies behind the ray
            let back = Ray::new(origin, -ray.direction);
            away += 1;
            away_turned += cull(&back, &tri).0 as u32;
            // Beside edge ab, as far out as the triangle is wide there
            let out = tri.normal.cross(b - a).normalize() * -(c - a).dot(tri.normal.cross(b - a).normalize());
            let ray = Ray::new(origin, ((a + b) * 0.5 + out - origin).normalize());
            if ray.direction.dot(tri.normal).abs() > 0.2 && out.length() > scale * 0.1 {
                beside += 1;
                beside_turned += cull(&ray, &tri).0 as u32;
            }
        }
        assert!(hits > 20_000 && sure > 5_000, "{hits} hits, {sure} sure");
        // The bound is not so loose that it could not fail
        assert!(worst > 1e-2, "the sure hits' points lie within {worst:e} of their bound");
        assert!(away > 5_000 && away_turned == away, "{away_turned} of {away} rays sent away turned away");
        assert!(
            beside > 3_000 && beside_turned == beside,
            "{beside_turned} of {beside} rays beside an edge turned away"
        );
    }

    /// Rays leaving the plane of a run of triangles (`cull::leaving`): the
    /// cull turns away every ray spawned off a hit on the run (from a point
    /// at least half the run's scale from the origin, as the margin allows),
    /// and never a ray the watertight test hits. Quads at scales 1e-6 … 1e6,
    /// their second triangle off the shared plane by up to 3 ulps; the rays
    /// start from 1/256 to 16 margins off the plane on either side, either
    /// way, steep or grazing. With no margin a ray starting between the
    /// plane and the lifted corner, its hit, is turned away; with five times
    /// the margin, spawned rays are not.
    #[test]
    fn rays_leaving_a_plane_are_turned_away_and_never_a_hit() {
        use crate::geometry::offset_ray_origin;
        let mut uniform = uniform_stream(0x9e37_79b9_7f4a_7c15);
        let turned_away = |ray: &Ray, tri: &Triangle| cull(ray, tri).0;
        let point =
            |uniform: &mut dyn FnMut() -> f32| Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5) * 2.0;
        let (mut spawned, mut near, mut hits, mut left) = (0, 0, 0, 0);
        for case in 0..20_000 {
            let scale = 10f32.powf(uniform() * 12.0 - 6.0);
            let corner = point(&mut uniform) * scale * 4.0;
            let (u, v) = (point(&mut uniform) * scale, point(&mut uniform) * scale);
            // The fourth corner lifted off the plane by up to 3 of the 4 ulps
            // a run allows
            let lift = u.cross(v).normalize_or_zero() * (uniform() * 2.0 - 1.0) * 3.0 * f32::EPSILON;
            let quad = [corner, corner + u, corner + u + v, corner + v + lift * (corner + u + v).abs().max_element()];
            let mut run = [Triangle::new(quad[0], quad[1], quad[2]), Triangle::new(quad[0], quad[2], quad[3])];
            Triangle::share_planes(&mut run.iter_mut().collect::<Vec<_>>());
            if run[0].is_degenerate() || run[1].cull.plane != run[0].cull.plane {
                continue;
            }
            let plane = run[0].cull.plane;
            let [a, b, c] = run[1].vertices;
            let (b1, b2) = (uniform(), uniform());
            let (b1, b2) = if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
            let on = a + (b - a) * b1 + (c - a) * b2;
            let side = if uniform() < 0.5 { 1.0 } else { -1.0 };
            // Half of them within a degree of the normal (where the
            // watertight test finds the triangle lying a few ulps off the
            // plane), half down to grazing (a cosine of 1e-4)
            let cos = if case % 2 == 0 { 1.0 - 1e-4 * uniform() } else { 10f32.powf(-4.0 * uniform()) };
            let along = plane
                .normal
                .cross(point(&mut uniform))
                .try_normalize()
                .unwrap_or(plane.normal.any_orthonormal_vector());
            let away = (plane.normal * (side * cos) + along * (1.0 - cos * cos).sqrt()).normalize();
            // Spawned off a hit, the way every integrator spawns its rays
            let arriving = Ray::new(on + away * scale, -away);
            if let Some(hit) = intersect_triangle(&arriving, &run[1], f32::INFINITY) {
                let ray = Ray::new(offset_ray_origin(hit.point, hit.error, hit.normal, away), away);
                if on.abs().max_element() >= plane.scale * 0.5 {
                    spawned += 1;
                    for tri in &run {
                        assert!(turned_away(&ray, tri), "case {case}: spawned {ray:?} not turned away by {tri:?}");
                    }
                }
            }
            // From just off the plane, either way, near the lifted corner
            // (where the triangle lies furthest off the plane) half the time
            let on = if case % 4 < 2 { on } else { c + (on - c) * 0.01 };
            let size = on.abs().element_sum();
            let margin = size * 4.0 * f32::EPSILON + plane.scale * 18.0 * f32::EPSILON;
            let height = side * margin * 2f32.powf(uniform() * 12.0 - 8.0);
            let direction = if uniform() < 0.5 { away } else { -away };
            let ray = Ray::new(on + plane.normal * height, direction);
            for tri in &run {
                near += 1;
                let turned = turned_away(&ray, tri);
                if watertight(&ray, tri, f32::INFINITY).is_some() {
                    hits += 1;
                    assert!(!turned, "case {case}: a hit turned away by the cull of {tri:?}, ray {ray:?}");
                } else if turned && direction.dot(plane.normal) * height > 0.0 {
                    left += 1;
                }
            }
        }
        assert!(spawned > 5_000, "{spawned} spawned rays");
        assert!(hits > 2_000 && left > 5_000, "{hits} hits and {left} rays leaving turned away of {near}");
    }

    /// Triangles in one plane share it, with the run's scale; the edges of
    /// each are its own, and a triangle off the plane starts a run of its
    /// own.
    #[test]
    fn runs_of_coplanar_triangles_share_a_plane() {
        let quad =
            [Vec3::new(1.0, 0.0, -3.0), Vec3::new(1.0, 0.0, 3.0), Vec3::new(1.0, 2.5, 3.0), Vec3::new(1.0, 2.5, -3.0)];
        let mut triangles = [
            Triangle::new(quad[0], quad[1], quad[2]),
            Triangle::new(quad[0], quad[2], quad[3]),
            Triangle::new(quad[0], quad[1], Vec3::new(2.0, 1.0, 0.0)),
        ];
        let alone = triangles.map(|t| t.cull);
        Triangle::share_planes(&mut triangles.iter_mut().collect::<Vec<_>>());
        assert_eq!(triangles[0].cull.plane, triangles[1].cull.plane);
        assert_eq!(triangles[0].cull.plane.drop, 0);
        assert_eq!(triangles[0].cull.plane.scale, 3.0);
        assert_ne!(triangles[1].cull.edges, triangles[0].cull.edges);
        assert_eq!(triangles[2].cull, alone[2]);
        // Through the quad's shared diagonal: both let the ray through
        let ray = Ray::new(Vec3::new(-1.0, 1.25, 0.0), Vec3::X);
        for t in &triangles[..2] {
            let crossing = Crossing::<f32>::of(ray.origin.into(), ray.direction.into(), &t.cull.plane);
            assert!(!crossing.test(&t.cull.edges.splat(), f32::INFINITY).0);
        }
    }

    #[test]
    fn degenerate_triangles_never_hit() {
        let collinear = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        let far = Triangle::new(Vec3::splat(1e7), Vec3::splat(1e7) + Vec3::X, Vec3::splat(1e7) + Vec3::X * 2.0);
        for tri in [collinear, point, far] {
            assert!(tri.is_degenerate());
            for dir in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, 0.4, -0.5).normalize()] {
                let ray = Ray::new(Vec3::new(0.5, 0.0, 1.0), dir);
                assert!(intersect_triangle(&ray, &tri, f32::INFINITY).is_none());
            }
        }
    }

    #[test]
    fn shared_edge_is_hit_by_at_least_one_triangle() {
        let a = Vec3::new(-1.0, -1.0, 0.0);
        let b = Vec3::new(1.0, -1.0, 0.0);
        let c = Vec3::new(1.0, 1.0, 0.0);
        let d = Vec3::new(-1.0, 1.0, 0.0);
        let (t0, t1) = (Triangle::new(a, b, c), Triangle::new(a, c, d));
        for i in 0..1000 {
            // Interior of the shared diagonal (its ends are the square's corners)
            let s = i as f32 / 999.0 * 1.98 - 0.99;
            let ray =
                Ray::new(Vec3::new(s, s, 1.0) + Vec3::new(0.1, -0.2, 0.0), Vec3::new(-0.1, 0.2, -1.0).normalize());
            let hits = [&t0, &t1].iter().filter(|t| intersect_triangle(&ray, t, f32::INFINITY).is_some()).count();
            assert!(hits >= 1, "ray {i} fell through the diagonal");
        }
    }
}
