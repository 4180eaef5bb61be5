//! Where a ray crosses a triangle's plane, the cheap test before the
//! watertight one. Triangles that share a plane share the crossing: a ray
//! computes it once for them all (the lanes do, over a run of coplanar
//! triangles), then each triangle asks only whether the crossing lies
//! within its three edges, two multiplies an edge in the plane's two kept
//! axes. Unlike a bounding ball, which a ray passing beside a large
//! triangle enters, the crossing turns away every ray but those that land
//! on or near the triangle.
//!
//! The test is conservative by a slack far above the rounding of the
//! crossing, of the edges and of the watertight test itself on any ray the
//! tests run here, so a ray that lands on the triangle is never turned away
//! (and a mesh stays watertight: both sides of a shared edge let its rays
//! through). It also says which lanes land inside by more than the slack,
//! well within their segment: the watertight test could only agree, so a
//! shadow ray there is blocked without it, and a ray looking for its
//! nearest hit takes the crossing, put back onto the plane, as its hit
//! (`CullPlane::hit_point`). Only rays near an edge pay for the watertight
//! test. Nor do rays leaving the plane, those spawned off its triangles
//! above all, whose crossing lies just behind them (`leaving`).
//!
//! One case it decides differently: a triangle seen from more than about
//! a thousand times its size, whose watertight edge functions (products
//! of coordinates that size, relative to the ray) err by a good part of
//! the triangle. The watertight test then finds hits beside the triangle
//! and misses inside it; the cull turns the first away and, for shadow
//! rays, blocks the second. No preset comes near it, and the lanes and the
//! scalar code decide alike.

use glam::{DVec2, DVec3, Vec3};

use super::plane::plane_point_of;
use super::real::{Mask, Real, V3};

/// The slack, relative to the magnitudes the crossing is computed from
/// (about 128 ulps): rounding of the crossing, of the f32 plane and edges
/// and of a triangle lying off its run's plane by `Triangle::holds_in_plane`'s
/// 4 ulps come to a few ulps of them each.
const SLACK: f32 = 1.0 / 65536.0;

/// A plane as rays cross it: the one plane of a run of coplanar triangles
/// (`Triangle::share_planes`), copied into each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CullPlane {
    /// Unit normal and offset: `normal · x = offset` on the plane.
    pub normal: Vec3,
    pub offset: f32,
    /// The largest coordinate of any triangle in the plane, in magnitude:
    /// the scale of the crossing's rounding.
    pub scale: f32,
    /// The axis the plane's triangles are projected along (the normal's
    /// largest): 0, 1 or 2.
    pub drop: usize,
}

/// A triangle's edges in its plane's two kept axes: the crossing (u, v) lies
/// inside where `a·u + b·v + c ≥ 0` for all three, (a, b) a unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CullEdges(pub [[f32; 3]; 3]);

/// A triangle's plane and edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleCull {
    pub plane: CullPlane,
    pub edges: CullEdges,
}

impl CullPlane {
    /// Where rays sure to hit a triangle of the plane (`Crossing::test`'s
    /// second mask) meet it, at their crossing `t`: the point put back onto
    /// the plane as a plane's hit is (`plane_point_of`), and a bound on its
    /// error that also covers the triangle lying off the plane it shares by
    /// rounding (`Triangle::holds_in_plane`'s 4 ulps of its scale, the
    /// plane's own rounding as much again).
    #[inline(always)]
    pub fn hit_point<R: Real>(&self, origin: V3<R>, direction: V3<R>, t: R) -> (V3<R>, R) {
        let normal = V3::new(R::splat(self.normal.x), R::splat(self.normal.y), R::splat(self.normal.z));
        let (point, error) = plane_point_of(origin, direction, normal, R::splat(self.offset), t);
        (point, error + R::splat(8.0 * f32::EPSILON * self.scale))
    }
}

impl TriangleCull {
    /// For `vertices` (not degenerate) in `plane`.
    pub fn new(vertices: [Vec3; 3], plane: CullPlane) -> Self {
        let flat = |v: Vec3| {
            let v = v.as_dvec3();
            match plane.drop {
                0 => DVec2::new(v.y, v.z),
                1 => DVec2::new(v.x, v.z),
                _ => DVec2::new(v.x, v.y),
            }
        };
        let q = vertices.map(flat);
        let inward = if (q[1] - q[0]).perp_dot(q[2] - q[0]) >= 0.0 { 1.0 } else { -1.0 };
        let edges = [0, 1, 2].map(|k| {
            let (from, to) = (q[k], q[(k + 1) % 3]);
            let along = to - from;
            // A degenerate triangle (never tested) keeps finite edges
            let normal = DVec2::new(-along.y, along.x) * (inward / along.length().max(f64::MIN_POSITIVE));
            [normal.x as f32, normal.y as f32, -normal.dot(from) as f32]
        });
        TriangleCull { plane, edges: CullEdges(edges) }
    }

    /// The plane through `vertices` with unit `normal`, for triangles up
    /// to `scale` in coordinate magnitude.
    pub fn plane_of(vertices: [Vec3; 3], normal: Vec3, scale: f32) -> CullPlane {
        let offset = normal.as_dvec3().dot(vertices.iter().map(|v| v.as_dvec3()).sum::<DVec3>() / 3.0) as f32;
        CullPlane { normal, offset, scale, drop: normal.abs().max_position() }
    }
}

/// Where rays cross a plane: the distance along each, the point in the
/// plane's two kept axes, and the slack the tests allow it.
#[derive(Clone, Copy)]
pub struct Crossing<R: Real> {
    pub t: R,
    pub u: R,
    pub v: R,
    pub slack: R,
}

impl<R: Real> Crossing<R> {
    /// Where each ray crosses the plane (`normal`, `offset`, `scale`); the
    /// caller keeps two axes of the point (as `of` does). Rays along
    /// the plane get an infinite or NaN distance and slack, which no test
    /// turns away. A ray surely leaving the plane (`leaving`) crosses it
    /// nowhere ahead: its distance is −∞, which every test turns away.
    #[inline(always)]
    pub fn point_of(origin: V3<R>, direction: V3<R>, normal: V3<R>, offset: R, scale: R) -> (R, V3<R>, R) {
        let across = normal.dot(direction);
        let rise = offset - normal.dot(origin);
        let t = rise / across;
        let point = origin + direction * t;
        let size = origin.abs().element_sum();
        let magnitude = size + t.abs() + scale;
        let t = R::select(leaving(t, rise, size, scale), R::splat(f32::NEG_INFINITY), t);
        (t, point, magnitude * SLACK / across.abs())
    }

    /// One plane's crossing for every lane.
    #[inline(always)]
    pub fn of(origin: V3<R>, direction: V3<R>, plane: &CullPlane) -> Self {
        let normal = V3::new(R::splat(plane.normal.x), R::splat(plane.normal.y), R::splat(plane.normal.z));
        let (t, point, slack) =
            Self::point_of(origin, direction, normal, R::splat(plane.offset), R::splat(plane.scale));
        let (u, v) = match plane.drop {
            0 => (point.y, point.z),
            1 => (point.x, point.z),
            _ => (point.x, point.y),
        };
        Crossing { t, u, v, slack }
    }

    /// Lanes that may hit the triangle of `edges` within (0, t_max), and
    /// those that surely do: their crossing inside every edge and within
    /// the segment by more than the slack. Comparisons are written so that
    /// a NaN lets a ray through and is never sure.
    #[inline(always)]
    pub fn test(&self, edges: &[[R; 3]; 3], t_max: R) -> (R::Mask, R::Mask) {
        let Crossing { t, u, v, slack } = *self;
        let outside = -slack;
        let mut turned_away = t.lt(outside).or(beyond(t, slack, t_max));
        let mut sure = t.gt(slack).and((t + slack).lt(t_max));
        for [a, b, c] in *edges {
            let e = a * u + b * v + c;
            turned_away = turned_away.or(e.lt(outside));
            sure = sure.and(e.gt(slack));
        }
        (turned_away, sure)
    }
}

/// Lanes whose ray moves away from the plane (a crossing behind it, at
/// `t < 0`) from further off it than the plane's triangles can lie (8 ulps
/// of its `scale`, `CullPlane::hit_point`) and than the `rise` to it, from
/// an origin of coordinates summing to `size`, can err (2 ulps of `size`
/// and one of the scale): each bound doubled. No triangle of the plane lies
/// ahead of them, so the watertight test could only miss. These are the
/// rays leaving a triangle of the plane: spawned off it by 128 ulps of the
/// point or more (`offset_origin`), far more than the margin unless the
/// point lies much nearer the origin than the plane's scale, their
/// crossing lies behind them by less than the slack, and the test turned
/// none away.
#[inline(always)]
fn leaving<R: Real>(t: R, rise: R, size: R, scale: R) -> R::Mask {
    let margin = size * (4.0 * f32::EPSILON) + scale * (18.0 * f32::EPSILON);
    t.lt(R::splat(0.0)).and(rise.abs().gt(margin))
}

/// Lanes whose crossing at `t` lies beyond `t_max` by more than the
/// slack: the part of `Crossing::test` a nearer `t_max` changes.
#[inline(always)]
pub fn beyond<R: Real>(t: R, slack: R, t_max: R) -> R::Mask {
    (t - slack).gt(t_max)
}

impl CullEdges {
    /// The edges splat into every lane.
    #[inline(always)]
    pub fn splat<R: Real>(&self) -> [[R; 3]; 3] {
        // Written out: `map`'s closures are left out of line, without AVX2
        let [e0, e1, e2] = self.0;
        [splat3(e0), splat3(e1), splat3(e2)]
    }
}

#[inline(always)]
fn splat3<R: Real>([a, b, c]: [f32; 3]) -> [R; 3] {
    [R::splat(a), R::splat(b), R::splat(c)]
}
