use glam::Vec3;

use super::real::{Real, V3};

/// A ray `x(t) = origin + t·direction`, `direction` unit length, `t ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl Ray {
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self { origin, direction }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }
}

/// pbrt's γ(n) = n·ε / (1 − n·ε), ε half of `f32::EPSILON`: the relative error
/// bound of n chained f32 operations.
#[inline]
pub const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5 * n as f32;
    e / (1.0 - e)
}

/// Offset that covers the rounding of a point of this magnitude: 256 ulps of
/// its largest coordinate (Wächter & Binder, Ray Tracing Gems ch. 6). Their
/// fixed floor near the origin is lowered to points within 2⁻⁶⁰ (about
/// 1e-18) of it, which take that magnitude's offset, 2⁻⁷⁵: each shape
/// reports its own error bound, so the offset can stay relative and tiny
/// scenes keep working. Below it the offset, and its products with the
/// numbers a ray meets, would be subnormal, and each subnormal operand or
/// result costs x86 a microcode assist of a hundred cycles or more. The
/// lanes of paths that have ended sit at the origin and still spawn shadow
/// rays, eight lanes at a time, most of all where paths leave the scene.
#[inline(always)]
pub fn spawn_offset_scale<R: Real>(p: V3<R>) -> R {
    const ULPS: f32 = 256.0;
    const SMALLEST: f32 = 1.0 / (1u64 << 60) as f32;
    let m = p.abs().max_element().max(R::splat(SMALLEST));
    // ulp(m) from the exponent: exact and cheap
    m.binade_ulp() * ULPS
}

/// Move a point computed on a surface off it, to the side `direction` points
/// to, by its error bound plus a magnitude-scaled margin, so a ray spawned there
/// never finds the surface it started on. A fixed epsilon fails both ways: acne
/// on large scenes, light leaks through thin shells on small ones.
#[inline]
pub fn offset_ray_origin(point: Vec3, error: f32, normal: Vec3, direction: Vec3) -> Vec3 {
    offset_origin(point.into(), error, normal.into(), direction.into()).into()
}

/// `offset_ray_origin` for one point or several.
#[inline(always)]
pub fn offset_origin<R: Real>(point: V3<R>, error: R, normal: V3<R>, direction: V3<R>) -> V3<R> {
    let distance = error * normal.abs().element_sum() + spawn_offset_scale(point);
    let offset = V3::select(direction.dot(normal).lt(R::splat(0.0)), -normal * distance, normal * distance);
    point + offset
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_scale_grows_with_magnitude() {
        let scale = |v: f32| spawn_offset_scale(V3::from(Vec3::splat(v)));
        assert!(scale(1.0e6) > scale(1.0) * 1.0e5);
        assert!(scale(1e-8) < 1e-12);
        // Never subnormal, at the origin and around it
        for m in [0.0, f32::from_bits(1), f32::MIN_POSITIVE, 1e-35, 1e-25, 2f32.powi(-60), 2f32.powi(-59)] {
            assert!(scale(m) >= 2f32.powi(-75), "offset {:e} at {m:e}", scale(m));
        }
        assert_eq!(scale(0.0), 2f32.powi(-75));
        assert_eq!(scale(2f32.powi(-59)), 2f32.powi(-74));
    }

    #[test]
    fn offset_goes_to_the_side_of_the_direction() {
        let n = Vec3::Y;
        let p = Vec3::new(3.0, 0.0, -2.0);
        assert!(offset_ray_origin(p, 0.0, n, Vec3::Y).y > 0.0);
        assert!(offset_ray_origin(p, 0.0, n, -Vec3::Y).y < 0.0);
    }
}
