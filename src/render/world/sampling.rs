//! Warps from the unit square to directions and points, with their pdfs.

use std::f32::consts::{FRAC_1_PI, FRAC_2_PI, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::geometry::real::{Mask, Real, V3};

/// 1.5·2²³: a float this size has unit spacing, so adding it rounds to an integer.
pub(crate) const ROUND_BY_ADDING: f32 = 12_582_912.0;

/// sin x and cos x together, inline: the warps below call them once per
/// sample, and libm's `sincosf` is out of line (a call per sample). Reduced
/// to |r| ≤ π/4 by quadrant (π/2 split in three, Cody–Waite, so r stays exact
/// for the |x| ≤ 2π the warps pass), then cephes' minimax polynomials: within
/// 2·10⁻⁷ of the true values.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    sin_cos_of(x)
}

/// `sin_cos` for one number or several.
#[inline(always)]
pub fn sin_cos_of<R: Real>(x: R) -> (R, R) {
    const PI_2_HI: f32 = 1.570_312_5;
    const PI_2_MID: f32 = 4.837_513e-4;
    const PI_2_LO: f32 = 7.549_79e-8;
    // Round to nearest by adding 1.5·2²³: the sum's last mantissa bits are
    // the quadrant k (mod 4, negatives included). No float-to-int
    // conversion: `f32::round` is a libm call without SSE4.1, and the
    // saturating `as i32` does not vectorise. Good for |x| < 2²¹.
    let shifted = x * FRAC_2_PI + ROUND_BY_ADDING;
    let quadrant = shifted - ROUND_BY_ADDING;
    let r = ((x - quadrant * PI_2_HI) - quadrant * PI_2_MID) - quadrant * PI_2_LO;
    let (sin, cos) = sin_cos_reduced(r);
    // k odd swaps sine and cosine; sine is negative where bit 1 of k is
    // set, cosine where k's two low bits differ
    let swap = shifted.bits_set(1);
    let sin_negative = shifted.bits_set(2);
    let cos_negative = swap.xor(sin_negative);
    let (s, c) = (R::select(swap, cos, sin), R::select(swap, sin, cos));
    (R::select(sin_negative, -s, s), R::select(cos_negative, -c, c))
}

/// `sin_cos` for |r| ≤ π/4: cephes' minimax polynomials alone.
#[inline(always)]
pub fn sin_cos_reduced<R: Real>(r: R) -> (R, R) {
    let r2 = r * r;
    // The coefficients' additions written as the scalar code had them:
    // a + b and b + a round alike, a − b and −b + a too
    let one = R::splat(1.0);
    let sin = r + r * r2 * (r2 * (r2 * -1.951_529_6e-4 + 8.332_161e-3) + -1.666_665_5e-1);
    let cos = (one - r2 * 0.5) + r2 * r2 * (r2 * (r2 * 2.443_315_7e-5 + -1.388_731_6e-3) + 4.166_664_6e-2);
    (sin, cos)
}

/// Shirley–Chiu concentric map: low distortion, so stratification survives.
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let (x, y) = concentric_disk_of(u.x, u.y);
    Vec2::new(x, y)
}

/// `concentric_disk` for one point or several. The angle is φ = π/4 · ratio
/// in the wide wedges and π/2 − φ in the tall ones, whose sine and cosine
/// are φ's swapped: no range reduction. The ratio is the smaller magnitude
/// over the larger with the quotient's sign (bit for bit oy/ox or ox/oy): a
/// division of selected lanes would split into lane-by-lane branches.
#[inline(always)]
pub fn concentric_disk_of<R: Real>(u0: R, u1: R) -> (R, R) {
    let (ox, oy) = (u0 * 2.0 - 1.0, u1 * 2.0 - 1.0);
    let zero = R::splat(0.0);
    let centre = ox.eq(zero).and(oy.eq(zero));
    let (ax, ay) = (ox.abs(), oy.abs());
    let wide = ax.gt(ay);
    let r = R::select(wide, ox, oy);
    let ratio = (ax.min(ay) / ax.max(ay)).copysign(ox * oy);
    let (sin, cos) = sin_cos_reduced(ratio * FRAC_PI_4);
    let dx = R::select(centre, zero, r * R::select(wide, cos, sin));
    let dy = R::select(centre, zero, r * R::select(wide, sin, cos));
    (dx, dy)
}

/// Cosine-weighted direction about +z; pdf = cos θ / π.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    cosine_hemisphere_of(u.x, u.y).into()
}

/// `cosine_hemisphere` for one sample or several.
#[inline(always)]
pub fn cosine_hemisphere_of<R: Real>(u0: R, u1: R) -> V3<R> {
    let (dx, dy) = concentric_disk_of(u0, u1);
    let z = (R::splat(1.0) - (dx * dx + dy * dy)).max(R::splat(0.0)).sqrt();
    V3::new(dx, dy, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cosine_hemisphere_pdf_of(cos_theta)
}

/// `cosine_hemisphere_pdf` for one direction or several.
#[inline(always)]
pub fn cosine_hemisphere_pdf_of<R: Real>(cos_theta: R) -> R {
    cos_theta.max(R::splat(0.0)) * FRAC_1_PI
}

/// Uniform direction on the unit sphere; pdf = 1 / 4π.
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    uniform_sphere_of(u.x, u.y).into()
}

/// `uniform_sphere` for one sample or several.
#[inline(always)]
pub fn uniform_sphere_of<R: Real>(u0: R, u1: R) -> V3<R> {
    let z = R::splat(1.0) - u0 * 2.0;
    let r = (R::splat(1.0) - z * z).max(R::splat(0.0)).sqrt();
    let (sin, cos) = sin_cos_of(u1 * (2.0 * PI));
    V3::new(r * cos, r * sin, z)
}

/// The density of `uniform_sphere`: 1/(4π) per steradian.
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Uniform direction in a cone about +z, given `1 − cos θmax` (passed as
/// such because it cancels to nothing in f32 for small, distant lights);
/// pdf = 1 / (2π(1 − cos θmax)).
#[inline]
pub fn uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    uniform_cone_of(u.x, u.y, one_minus_cos_max).into()
}

/// `uniform_cone` for one sample or several.
#[inline(always)]
pub fn uniform_cone_of<R: Real>(u0: R, u1: R, one_minus_cos_max: R) -> V3<R> {
    let one_minus_cos = u0 * one_minus_cos_max;
    let cos_theta = R::splat(1.0) - one_minus_cos;
    let sin_theta = (one_minus_cos * (R::splat(2.0) - one_minus_cos)).max(R::splat(0.0)).sqrt();
    let (sin, cos) = sin_cos_of(u1 * (2.0 * PI));
    V3::new(sin_theta * cos, sin_theta * sin, cos_theta)
}

#[inline]
pub fn uniform_cone_pdf(one_minus_cos_max: f32) -> f32 {
    uniform_cone_pdf_of(one_minus_cos_max)
}

/// `uniform_cone_pdf` for one cone or several.
#[inline(always)]
pub fn uniform_cone_pdf_of<R: Real>(one_minus_cos_max: R) -> R {
    R::splat(1.0) / (R::splat(2.0 * PI) * one_minus_cos_max)
}

/// Direction about +z with pdf ∝ cosⁿθ: pdf = (n + 1)/(2π) · cosⁿθ.
#[inline]
pub fn power_cosine(u: Vec2, exponent: f32) -> Vec3 {
    power_cosine_of(u.x, u.y, exponent).into()
}

/// `power_cosine` for one sample or several.
#[inline(always)]
pub fn power_cosine_of<R: Real>(u0: R, u1: R, exponent: R) -> V3<R> {
    let cos_theta = u0.powf(R::splat(1.0) / (exponent + 1.0));
    let sin_theta = (R::splat(1.0) - cos_theta * cos_theta).max(R::splat(0.0)).sqrt();
    let (sin, cos) = sin_cos_of(u1 * (2.0 * PI));
    V3::new(sin_theta * cos, sin_theta * sin, cos_theta)
}

#[inline]
pub fn power_cosine_pdf(cos_theta: f32, exponent: f32) -> f32 {
    power_cosine_pdf_of(cos_theta, exponent)
}

/// `power_cosine_pdf` for one direction or several.
#[inline(always)]
pub fn power_cosine_pdf_of<R: Real>(cos_theta: R, exponent: R) -> R {
    let pdf = (exponent + 1.0) * 0.5 * FRAC_1_PI * cos_theta.powf(exponent);
    R::select(cos_theta.le(R::splat(0.0)), R::splat(0.0), pdf)
}

/// Uniform barycentrics (b0, b1) on a triangle (b2 = 1 − b0 − b1).
#[inline]
pub fn uniform_triangle(u: Vec2) -> (f32, f32) {
    uniform_triangle_of(u.x, u.y)
}

/// `uniform_triangle` for one sample or several.
#[inline(always)]
pub fn uniform_triangle_of<R: Real>(u0: R, u1: R) -> (R, R) {
    let su = u0.sqrt();
    (R::splat(1.0) - su, u1 * su)
}

/// Veach's power heuristic with β = 2; an infinite `pdf_f` (a delta
/// light) weighs 1, a degenerate pair 0.
#[inline]
pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    power_heuristic_of(pdf_f, pdf_g)
}

/// `power_heuristic` for one pair or several.
#[inline(always)]
pub fn power_heuristic_of<R: Real>(pdf_f: R, pdf_g: R) -> R {
    let (f, g) = (pdf_f * pdf_f, pdf_g * pdf_g);
    let sum = f + g;
    let fallback = R::select(pdf_f.abs().eq(R::splat(f32::INFINITY)), R::splat(1.0), R::splat(0.0));
    R::select(sum.ne(R::splat(0.0)).and(f.is_finite()), f / sum, fallback)
}

#[cfg(test)]
mod tests {
    use std::f32::consts::FRAC_PI_2;

    use super::*;
    use crate::render::world::rng::Sampler;

    #[test]
    fn warps_land_where_they_should() {
        let mut s = Sampler::new(0, 0, 9);
        for _ in 0..10_000 {
            let u = s.next_2d();
            let c = cosine_hemisphere(u);
            assert!((c.length() - 1.0).abs() < 1e-5 && c.z >= 0.0);
            assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            let cone = uniform_cone(u, 0.1);
            assert!(cone.z >= 0.9 - 1e-6);
            let (b0, b1) = uniform_triangle(u);
            assert!(b0 >= 0.0 && b1 >= 0.0 && b0 + b1 <= 1.0 + 1e-6);
        }
    }

    /// Against f64 over the warps' range and beyond, and at the quadrant seams.
    #[test]
    fn sin_cos_matches_f64() {
        let mut worst = 0.0f64;
        let seams = (-8..=8).map(|k| k as f32 * FRAC_PI_4);
        let grid = (0..=200_000).map(|i| -7.0 + 14.0 * i as f32 / 200_000.0);
        for x in grid.chain(seams).flat_map(|x| [x, x.next_up(), x.next_down()]) {
            let (sin, cos) = sin_cos(x);
            let exact = (x as f64).sin_cos();
            worst = worst.max((sin as f64 - exact.0).abs()).max((cos as f64 - exact.1).abs());
        }
        assert!(worst < 2e-7, "worst error {worst}");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    /// Against Shirley–Chiu's map as written (r, θ), in f64: the swapped
    /// sine and cosine of the tall wedges put points where θ says.
    #[test]
    fn concentric_disk_matches_the_map_in_f64() {
        let mut s = Sampler::new(3, 1, 4);
        let corners = [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.75, 0.5], [0.5, 0.25], [0.5, 0.5]];
        for u in (0..50_000).map(|_| s.next_2d()).chain(corners.map(Vec2::from_array)) {
            let (x, y) = (2.0 * u.x as f64 - 1.0, 2.0 * u.y as f64 - 1.0);
            let expected = if x == 0.0 && y == 0.0 {
                (0.0, 0.0)
            } else if x.abs() > y.abs() {
                let theta = std::f64::consts::FRAC_PI_4 * (y / x);
                (x * theta.cos(), x * theta.sin())
            } else {
                let theta = std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (x / y);
                (y * theta.cos(), y * theta.sin())
            };
            let d = concentric_disk(u);
            let error = (d.x as f64 - expected.0).abs().max((d.y as f64 - expected.1).abs());
            assert!(error < 4e-7, "{u}: {d} against {expected:?}");
        }
    }

    #[test]
    fn power_cosine_integrates_to_one() {
        // ∫ pdf dω over the hemisphere by a Riemann sum in θ
        for n in [0.0f32, 1.0, 10.0, 200.0] {
            let steps = 20_000;
            let dtheta = FRAC_PI_2 / steps as f32;
            let total: f32 = (0..steps)
                .map(|i| {
                    let theta = (i as f32 + 0.5) * dtheta;
                    power_cosine_pdf(theta.cos(), n) * 2.0 * PI * theta.sin() * dtheta
                })
                .sum();
            assert!((total - 1.0).abs() < 1e-3, "n = {n}: {total}");
        }
    }
}
