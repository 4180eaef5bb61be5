//! xʸ written once for one number and for eight: the Phong lobes, their
//! sampling and spot lights raise to powers on every path. libm's `powf`
//! runs lane by lane (a sixth of a glossy scene's path tracing was spent
//! in it) and differs between platforms; this one is the same everywhere
//! and in every lane, and is within a few ulps of the exact power (the
//! bound is tested below against f64).

use std::f32::consts::SQRT_2;

use crate::geometry::real::{Mask, Real, ROUND_BY_ADDING};

/// 2/(k ln 2) for k = 1, 3, …, 13: log₂ m = Σ cₖ sᵏ with s = (m − 1)/(m + 1).
const LOG2_SERIES: [f32; 7] = [2.88539, 0.9617967, 0.57707804, 0.41219857, 0.3205989, 0.26230818, 0.22195308];

/// (ln 2)ʲ/j! for j = 1 … 7: 2ᶠ = 1 + Σ dⱼ fʲ.
const EXP2_SERIES: [f32; 7] =
    [std::f32::consts::LN_2, 0.2402265, 0.05550411, 0.009618129, 0.0013333558, 0.0001540353, 1.5252734e-05];

/// `x`ʸ for `x` ≥ 0 (NaN for negative `x`), with `powf`'s special cases:
/// x⁰ = 1ʸ = 1 (NaN too), 0ʸ = 0 or ∞, ∞ʸ = ∞ or 0. Elsewhere 2^(y log₂ x):
/// the logarithm from the atanh series on the mantissa in [√½, √2), the
/// power of two from its Taylor series on the fraction in [−½, ½], each
/// truncated below 2⁻²⁴ of its value.
#[inline(always)]
pub fn pow_of<R: Real>(x: R, y: R) -> R {
    let zero = R::splat(0.0);
    // Subnormals scaled into the normal range first
    let tiny = x.lt(R::splat(f32::MIN_POSITIVE));
    let (m, e) = R::select(tiny, x * 8_388_608.0, x).split_exponent();
    let e = R::select(tiny, e - 23.0, e);
    let high = m.gt(R::splat(SQRT_2));
    let (m, e) = (R::select(high, m * 0.5, m), R::select(high, e + 1.0, e));
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut series = R::splat(LOG2_SERIES[6]);
    for c in LOG2_SERIES[..6].iter().rev() {
        series = series * s2 + *c;
    }
    let log2_x = e + s * series;
    // Beyond ±150 the power is 0 or ∞ whatever the fraction
    let z = (y * log2_x).max(R::splat(-160.0)).min(R::splat(130.0));
    let whole = (z + ROUND_BY_ADDING) - ROUND_BY_ADDING;
    let f = z - whole;
    let mut power = R::splat(EXP2_SERIES[6]);
    for d in EXP2_SERIES[..6].iter().rev() {
        power = power * f + *d;
    }
    let power = power * f + 1.0;
    // 2^whole in two halves, each a normal float: one rounding, into the
    // subnormals where the power lies there
    let half = (whole * 0.5 + ROUND_BY_ADDING) - ROUND_BY_ADDING;
    let mut p = power * half.exp2_whole() * (whole - half).exp2_whole();
    let (infinity, nan) = (R::splat(f32::INFINITY), R::splat(f32::NAN));
    let negative_y = y.lt(zero);
    p = R::select(x.eq(zero), R::select(negative_y, infinity, zero), p);
    p = R::select(x.eq(infinity), R::select(negative_y, zero, infinity), p);
    p = R::select(x.lt(zero).or(x.ne(x)).or(y.ne(y)), nan, p);
    R::select(x.eq(R::splat(1.0)).or(y.eq(zero)), R::splat(1.0), p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// Within (4|z| + 8)·2⁻²⁴ of f64's power, relatively, z = y log₂ x (the
    /// logarithm's few roundings grow with the exponent they are multiplied
    /// into), or one subnormal step; beyond the largest float, infinite.
    /// Measured over 2 M such powers: at most 2.3·2⁻²⁴ for |z| < 1, and
    /// 1.9(|z| + 1)·2⁻²⁴ in all.
    fn within_bound(x: f32, y: f32) -> Result<(), String> {
        let got = pow_of(x, y) as f64;
        let exact = (x as f64).powf(y as f64);
        let z = (y as f64 * (x as f64).log2()).abs();
        let relative = (4.0 * z + 8.0) * 2f64.powi(-24);
        let agree = got == exact
            || match exact >= f32::MAX as f64 {
                true => got.is_infinite() || got >= exact * (1.0 - relative),
                false => (got - exact).abs() <= relative * exact + 2f64.powi(-149),
            };
        match agree {
            true => Ok(()),
            false => Err(format!("{x}^{y}: {got:e}, exactly {exact:e}")),
        }
    }

    /// Bases over every binade of (0, 1] and just above, the exponents the
    /// renderer uses (Phong's up to 10⁴, their sampling's 1/(n + 1), the
    /// radius schedule's), and the binades' edges.
    #[test]
    fn powers_agree_with_f64_within_the_bound() {
        let mut s = Sampler::new(0, 0, 17);
        for i in 0..200_000 {
            let binade = -((s.next_f32() * 150.0) as i32) as f32;
            let x = binade.exp2() * (1.0 + s.next_f32());
            let y = match i % 3 {
                0 => s.next_f32() * 10_000.0,
                1 => 1.0 / (s.next_f32() * 10_000.0 + 1.0),
                _ => s.next_f32() * 4.0 - 2.0,
            };
            within_bound(x, y).unwrap();
        }
        for x in [f32::MIN_POSITIVE, 1e-45, 0.5, SQRT_2, SQRT_2.next_up(), 1.0f32.next_down(), 1.0f32.next_up(), 7.0] {
            for y in [0.5, 1.0, 2.0, 3.0, 120.0, -1.0, 1e-3, 1e4] {
                within_bound(x, y).unwrap();
            }
        }
        // Whole powers of two are exact
        assert_eq!(pow_of(0.5f32, 3.0), 0.125);
        assert_eq!(pow_of(4.0f32, 0.5), 2.0);
        assert_eq!(pow_of(2.0f32, -149.0), f32::from_bits(1));
    }

    /// Where a base or an exponent is special, libm's answer bit for bit;
    /// negative bases (outside the renderer's use) give NaN.
    #[test]
    fn special_cases_are_powfs() {
        let bases = [0.0, 1.0, 0.5, 2.0, 1e-40, f32::INFINITY, f32::NAN, -1.0, -0.5];
        let exponents = [0.0, -0.0, 1.0, 0.5, 3.0, -1.0, -2.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        let mut checked = 0;
        for x in bases {
            for y in exponents {
                let got = pow_of(x, y);
                if x < 0.0 {
                    assert!(if y == 0.0 { got == 1.0 } else { got.is_nan() }, "{x}^{y}: {got}");
                    continue;
                }
                let special = x == 0.0 || x == 1.0 || !x.is_finite() || y == 0.0 || !y.is_finite();
                if special {
                    let libm = x.powf(y);
                    assert!(
                        got.to_bits() == libm.to_bits() || got.is_nan() && libm.is_nan(),
                        "{x}^{y}: {got}, libm {libm}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 50);
    }
}
