use glam::Vec3;

use super::real::{Mask, Real, V3};
use super::{gamma, Ray, SurfaceHit};

/// Nearest hit of `ray` with the sphere in (0, t_max).
///
/// The textbook `−b ± √(b² − c)` cancels catastrophically for large spheres
/// and distant rays; this is the stable form of Haines et al., Ray Tracing
/// Gems ch. 7: the discriminant from the ray's closest approach to the centre,
/// and the smaller root as `c / q`.
#[inline]
pub fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32, t_max: f32) -> Option<SurfaceHit> {
    let (t, near) = sphere_t(ray, center, radius, t_max)?;
    Some(sphere_hit(ray, center, radius, t, near))
}

/// The nearest root in (0, t_max) and whether it is the near one (entering),
/// without building the hit record (the nearest-hit loop only needs `t`).
/// Which root matters: from far away both round to the same `t`.
#[inline]
pub fn sphere_t(ray: &Ray, center: Vec3, radius: f32, t_max: f32) -> Option<(f32, bool)> {
    let f = V3::from(ray.origin - center);
    let (t, hit, near) = nearest_root(f, ray.direction.into(), radius * radius, t_max);
    hit.then_some((t, near))
}

/// The roots of a sphere of squared radius `radius2` along rays of unit
/// `direction`, from `f` = origin − centre: (near, far, discriminant). The
/// discriminant comes from the closest approach, the root that adds
/// magnitudes first and the other from Vieta (t0·t1 = c).
#[inline(always)]
pub fn roots<R: Real>(f: V3<R>, direction: V3<R>, radius2: R) -> (R, R, R) {
    let b = f.dot(direction);
    let closest = f - direction * b;
    let discriminant = radius2 - closest.length_squared();
    let c = f.length_squared() - radius2;
    let q = -b - discriminant.max(R::splat(0.0)).sqrt().copysign(b);
    let t0 = c / q;
    (t0.min(q), t0.max(q), discriminant)
}

/// The nearest root in (0, t_max): (t, whether there is one, whether it is
/// the near root). A ray starting inside takes the far root; q == 0 (a ray
/// through the centre starting on it) gives NaN, which no comparison passes.
#[inline(always)]
pub fn nearest_root<R: Real>(f: V3<R>, direction: V3<R>, radius2: R, t_max: R) -> (R, R::Mask, R::Mask) {
    let (near, far, discriminant) = roots(f, direction, radius2);
    let zero = R::splat(0.0);
    let near_ok = near.gt(zero).and(near.lt(t_max));
    let t = R::select(near_ok, near, far);
    let hit = discriminant.ge(zero).and(t.gt(zero)).and(t.lt(t_max));
    (t, hit, near_ok)
}

/// A sphere that holds the paths of a scene (an opaque wall the camera is
/// inside), written about the point of it nearest the scene: `anchor`, the
/// outward unit `normal` there, `radius`. Written about its centre, a wall
/// of radius 1e5 (smallpt's) puts every |o − c|² − r² of a ray from the
/// room at a difference of two numbers near 1e10, good in f32 only to
/// about 1e3: its hits come out 0.01–0.07 off, the offsets that keep the
/// next ray off the wall grow to match (smallpt renders too bright from
/// that alone), and where two walls meet a path may take the farther hit
/// and leave the room. About the anchor the same quantity is
/// |e|² + 2r(e · n), e = o − anchor, each term good to its own few ulps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnchoredSphere {
    pub anchor: Vec3,
    pub normal: Vec3,
    pub radius: f32,
}

impl AnchoredSphere {
    /// The sphere (`center`, `radius`) about its point nearest `near`
    /// (in f64: the anchor is as good as f32 can hold it).
    pub fn new(center: Vec3, radius: f32, near: Vec3) -> Self {
        let towards = (near.as_dvec3() - center.as_dvec3()).try_normalize().unwrap_or(glam::DVec3::Y);
        let anchor = center.as_dvec3() + towards * radius as f64;
        Self { anchor: anchor.as_vec3(), normal: towards.as_vec3(), radius }
    }
}

/// Where a ray from `origin` along unit `direction` leaves the wall
/// (`anchor`, `normal`, `radius`) that holds its path, in [0, t_max): the
/// far root, never the near one; and 0 — at once — where rounding has put
/// the origin outside and the ray heads away from the centre (it then meets
/// the wall on its inside, leaving it, and stays in the room). A ray from
/// just outside that heads in but whose line misses the ball (grazing it)
/// goes on into the room. (t, whether there is a hit below t_max.)
#[inline(always)]
pub fn wall_exit<R: Real>(
    origin: V3<R>,
    direction: V3<R>,
    anchor: V3<R>,
    normal: V3<R>,
    radius: R,
    t_max: R,
) -> (R, R::Mask) {
    wall_exit_along(origin, direction, anchor, normal, normal.dot(direction), radius, t_max)
}

/// `wall_exit` given `along`, the ray's n · d.
#[inline(always)]
pub fn wall_exit_along<R: Real>(
    origin: V3<R>,
    direction: V3<R>,
    anchor: V3<R>,
    normal: V3<R>,
    along: R,
    radius: R,
    t_max: R,
) -> (R, R::Mask) {
    let e = origin - anchor;
    // f = o − c = e + r·n, never formed: b = f · d, c = |f|² − r²
    let b = e.dot(direction) + radius * along;
    let c = e.dot(e) + (radius + radius) * e.dot(normal);
    let root = (b * b - c).max(R::splat(0.0)).sqrt();
    let zero = R::splat(0.0);
    // The larger root, from the side that adds magnitudes
    let heading_out = b.gt(zero);
    let far = R::select(heading_out, -c / (b + root), root - b);
    let leaving = (b * b - c).ge(zero).and(far.gt(zero));
    let t = R::select(leaving, far, zero);
    (t, leaving.or(heading_out).and(t.lt(t_max)))
}

/// The point where `wall_exit` found a ray (`origin`, `direction`) leaving
/// the wall about `center` at `t`, its outward normal, and a bound on the
/// point's error: set by the origin's scale (near the room, not near the
/// centre 1e5 away) and the wall's `slack` (`wall_slack`). The normal may
/// come from the centre: it needs the direction of p − c to about 1e-7,
/// not its length.
#[inline(always)]
pub fn wall_exit_hit<R: Real>(origin: V3<R>, direction: V3<R>, t: R, center: V3<R>, slack: R) -> (V3<R>, V3<R>, R) {
    let point = origin + direction * t;
    let outward = (point - center).normalize();
    let scale = origin.x.abs().max(origin.y.abs()).max(origin.z.abs()) + t;
    (point, outward, scale * R::splat(gamma(16)) + slack)
}

/// What a wall's exit points may err by besides their own rounding: the
/// anchor's, and the anchored sphere's departure from the one about the
/// centre (its normal is rounded too), which grow with the distance from
/// the anchor; `wall_exit_hit` adds it.
pub fn wall_slack(wall: &AnchoredSphere) -> f32 {
    gamma(16) * wall.anchor.abs().max_element()
}

/// The hit at `t` on a sphere, entering (`near`) or leaving it.
#[inline]
pub(crate) fn sphere_hit(ray: &Ray, center: Vec3, radius: f32, t: f32, near: bool) -> SurfaceHit {
    // Rebuild the point from the closest approach rather than origin + t·d:
    // from far away t is only good to ulp(t), the closest-approach vector to
    // ulp(radius).
    let f = ray.origin - center;
    let closest = f - f.dot(ray.direction) * ray.direction;
    let half_chord = (radius * radius - closest.length_squared()).max(0.0).sqrt();
    let from_center = if near { closest - half_chord * ray.direction } else { closest + half_chord * ray.direction };
    let length = from_center.length();
    let normal = if length > 0.0 { from_center / length } else { -ray.direction };
    SurfaceHit { t, point: center + normal * radius, normal, error: gamma(6) * (center.abs().max_element() + radius) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Nearest positive root in f64, the oracle for the f32 code.
    fn oracle(origin: DVec3, direction: DVec3, center: DVec3, radius: f64) -> Option<f64> {
        let d = direction.normalize();
        let f = origin - center;
        let b = f.dot(d);
        let disc = radius * radius - (f - b * d).length_squared();
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        [-b - s, -b + s].into_iter().find(|t| *t > 0.0)
    }

    #[test]
    fn tiny_sphere_from_ten_million_units() {
        let ray = Ray::new(Vec3::new(-1.0e7, 0.095, 0.0), Vec3::X);
        let hit = intersect_sphere(&ray, Vec3::ZERO, 0.1, f32::INFINITY).expect("must hit");
        let t = oracle(DVec3::new(-1.0e7, 0.095, 0.0), DVec3::X, DVec3::ZERO, 0.1).unwrap();
        // f32 cannot place the origin better than ulp(1e7) = 1, so t is good to ~1
        assert!((hit.t as f64 - t).abs() <= 1.0, "{} vs {t}", hit.t);
        assert!((hit.point.length() - 0.1).abs() < 1e-6);
        assert!(hit.normal.x < 0.0);
    }

    #[test]
    fn smallpt_walls_from_the_camera() {
        // Left wall of smallpt seen from inside the box
        let center = Vec3::new(1.0e5 + 1.0, 40.8, 81.6);
        let origin = Vec3::new(50.0, 52.0, 155.6);
        // The room is inside every wall's sphere: the wall at x = 1 is its near side
        for dir in [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(-1.0, -0.3, -0.2), Vec3::new(-0.6, 0.1, -1.0)] {
            let d = dir.normalize();
            let hit = intersect_sphere(&Ray::new(origin, d), center, 1.0e5, f32::INFINITY).unwrap();
            let t = oracle(origin.as_dvec3(), d.as_dvec3(), center.as_dvec3(), 1.0e5).unwrap();
            assert!((hit.t as f64 - t).abs() < 1e-3 * t.max(1.0), "{} vs {t}", hit.t);
            assert!(hit.point.x > 0.9 && hit.point.x < 1.1);
            assert!(hit.error >= 1e-3, "error bound must cover the centre's rounding");
        }
    }

    #[test]
    fn tangent_and_grazing_rays_stay_finite() {
        for y in [0.999_999f32, 1.0, 1.000_001, 0.9999] {
            let ray = Ray::new(Vec3::new(-5.0, y, 0.0), Vec3::X);
            if let Some(hit) = intersect_sphere(&ray, Vec3::ZERO, 1.0, f32::INFINITY) {
                assert!(hit.t.is_finite() && hit.point.is_finite() && hit.normal.is_finite());
                assert!((hit.point.length() - 1.0).abs() < 1e-5);
            }
        }
        assert!(
            intersect_sphere(&Ray::new(Vec3::new(-5.0, 1.001, 0.0), Vec3::X), Vec3::ZERO, 1.0, f32::INFINITY).is_none()
        );
    }

    #[test]
    fn from_inside_finds_the_far_side() {
        let ray = Ray::new(Vec3::ZERO, Vec3::Y);
        let hit = intersect_sphere(&ray, Vec3::ZERO, 2.0, f32::INFINITY).unwrap();
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert!(intersect_sphere(&ray, Vec3::ZERO, 2.0, 1.5).is_none());
    }

    /// smallpt's walls about their point nearest the camera: from random
    /// points in the room, the exit distance within 2e-6 of its length of
    /// the f64 answer (about its centre the f32 one errs by up to 0.07), the
    /// hit within its error bound of the f64 sphere, the bound under 1e-3
    /// near the room.
    #[test]
    fn walls_about_their_anchor_are_hit_as_f64_hits_them() {
        let eye = Vec3::new(50.0, 52.0, 155.6);
        let walls = [
            (Vec3::new(1.0e5 + 1.0, 40.8, 81.6), 1.0e5),
            (Vec3::new(50.0, -1.0e5 + 81.6, 81.6), 1.0e5),
            (Vec3::new(50.0, 40.8, -1.0e5 + 170.0), 1.0e5),
        ];
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for (center, radius) in walls {
            let wall = AnchoredSphere::new(center, radius, eye);
            for _ in 0..2000 {
                let origin = Vec3::new(2.0 + 96.0 * next(), 1.0 + 80.0 * next(), 1.0 + 168.0 * next());
                let d = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                let (t, hit) =
                    wall_exit(origin.into(), d.into(), wall.anchor.into(), wall.normal.into(), radius, f32::INFINITY);
                assert!(hit, "a ray from inside always leaves");
                let exact = oracle(origin.as_dvec3(), d.as_dvec3(), center.as_dvec3(), radius as f64).unwrap();
                assert!((t as f64 - exact).abs() <= 2e-6 * exact.max(1.0), "t {t} against {exact}");
                let (point, normal, error) =
                    wall_exit_hit(origin.into(), d.into(), t, center.into(), wall_slack(&wall));
                let point = Vec3::from(point).as_dvec3();
                let off = (point - center.as_dvec3()).length() - radius as f64;
                assert!(off.abs() <= error as f64, "{off} off the wall, bound {error}");
                // Near the room (not across the ball, 2e5 away) the bound is tight
                assert!(t > 400.0 || error < 1e-3, "bound {error} at t = {t}");
                assert!(Vec3::from(normal).dot(d) > 0.0, "the ray leaves through the wall");
            }
        }
    }

    /// Just outside a wall (by less than its old error bound), heading out:
    /// met at once; heading in: left on the far side; grazing in past the
    /// ball: not met.
    #[test]
    fn a_wall_holds_a_path_rounding_put_outside_it() {
        let (center, radius) = (Vec3::new(50.0, 40.8, 1.0e5), 1.0e5);
        let wall = AnchoredSphere::new(center, radius, Vec3::new(50.0, 40.0, 80.0));
        let exit = |origin: Vec3, d: Vec3| {
            wall_exit(
                origin.into(),
                d.normalize().into(),
                wall.anchor.into(),
                wall.normal.into(),
                radius,
                f32::INFINITY,
            )
        };
        let outside = Vec3::new(50.0, 40.8, -0.01);
        assert_eq!(exit(outside, -Vec3::Z), (0.0, true));
        let (t, hit) = exit(outside, Vec3::Z);
        assert!(hit && (t - 2.0e5).abs() < 100.0, "across the ball: {t}");
        // Heading in at 1e-4 of a radian from the tangent plane, 0.01 out:
        // the line passes outside the ball
        assert!(!exit(Vec3::new(50.0, 40.8, -0.01), Vec3::new(1.0, 0.0, 1e-4)).1);
    }
}
