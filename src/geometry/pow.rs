//! xʸ in f32, written once so that the scalar code and the lanes compute the
//! same bits on every machine: Arm's table-driven `powf` (optimized-routines,
//! MIT; the one musl and glibc ship), 2^(y · log₂ x) in f64 from a 16-entry
//! table for log₂ and a 32-entry one for 2^(j/32). It is evaluated here as
//! plain f64 multiplies and adds, never fused, so the eight lanes repeat it
//! exactly (`lanes::avx`); libm's own build differs by machine (glibc picks
//! a fused version on CPUs with FMA), and its result in the last bit with it.
//! Within 0.82 ulp of xʸ (Arm's bound) where that is a normal f32, and 0
//! below (`powf`); tested against f64 below.

/// `[1/c, log₂ c]` for the 16 subintervals of the mantissa's range (an
/// array, not a tuple: the lanes gather from it by offset).
pub(crate) const LOG2_TABLE: [[f64; 2]; 16] = [
    [f64::from_bits(0x3ff661ec79f8f3be), f64::from_bits(0xbfdefec65b963019)],
    [f64::from_bits(0x3ff571ed4aaf883d), f64::from_bits(0xbfdb0b6832d4fca4)],
    [f64::from_bits(0x3ff49539f0f010b0), f64::from_bits(0xbfd7418b0a1fb77b)],
    [f64::from_bits(0x3ff3c995b0b80385), f64::from_bits(0xbfd39de91a6dcf7b)],
    [f64::from_bits(0x3ff30d190c8864a5), f64::from_bits(0xbfd01d9bf3f2b631)],
    [f64::from_bits(0x3ff25e227b0b8ea0), f64::from_bits(0xbfc97c1d1b3b7af0)],
    [f64::from_bits(0x3ff1bb4a4a1a343f), f64::from_bits(0xbfc2f9e393af3c9f)],
    [f64::from_bits(0x3ff12358f08ae5ba), f64::from_bits(0xbfb960cbbf788d5c)],
    [f64::from_bits(0x3ff0953f419900a7), f64::from_bits(0xbfaa6f9db6475fce)],
    [1.0, 0.0],
    [f64::from_bits(0x3fee608cfd9a47ac), f64::from_bits(0x3fb338ca9f24f53d)],
    [f64::from_bits(0x3feca4b31f026aa0), f64::from_bits(0x3fc476a9543891ba)],
    [f64::from_bits(0x3feb2036576afce6), f64::from_bits(0x3fce840b4ac4e4d2)],
    [f64::from_bits(0x3fe9c2d163a1aa2d), f64::from_bits(0x3fd40645f0c6651c)],
    [f64::from_bits(0x3fe886e6037841ed), f64::from_bits(0x3fd88e9c2c1b9ff8)],
    [f64::from_bits(0x3fe767dcf5534862), f64::from_bits(0x3fdce0a44eb17bcc)],
];

/// log₂(1 + r) ≈ A₄r + A₃r² + A₂r³ + A₁r⁴ + A₀r⁵ for |r| < 1/32.
pub(crate) const LOG2_POLY: [f64; 5] = [
    f64::from_bits(0x3fd27616c9496e0b),
    f64::from_bits(0xbfd71969a075c67a),
    f64::from_bits(0x3fdec70a6ca7badd),
    f64::from_bits(0xbfe7154748bef6c8),
    f64::from_bits(0x3ff71547652ab82b),
];

/// Where `log2_of`'s table index and exponent are measured from: the
/// mantissa's range [0x1.66p-1, 0x1.66p0) is split into 16.
pub(crate) const LOG2_OFFSET: u32 = 0x3f33_0000;

/// The bits of 2^(j/32) less j << 47, so that adding k << 47 for any k
/// with k mod 32 = j gives the bits of 2^(k/32).
pub(crate) const EXP2_TABLE: [u64; 32] = [
    0x3ff0000000000000,
    0x3fefd9b0d3158574,
    0x3fefb5586cf9890f,
    0x3fef9301d0125b51,
    0x3fef72b83c7d517b,
    0x3fef54873168b9aa,
    0x3fef387a6e756238,
    0x3fef1e9df51fdee1,
    0x3fef06fe0a31b715,
    0x3feef1a7373aa9cb,
    0x3feedea64c123422,
    0x3feece086061892d,
    0x3feebfdad5362a27,
    0x3feeb42b569d4f82,
    0x3feeab07dd485429,
    0x3feea47eb03a5585,
    0x3feea09e667f3bcd,
    0x3fee9f75e8ec5f74,
    0x3feea11473eb0187,
    0x3feea589994cce13,
    0x3feeace5422aa0db,
    0x3feeb737b0cdc5e5,
    0x3feec49182a3f090,
    0x3feed503b23e255d,
    0x3feee89f995ad3ad,
    0x3feeff76f2fb5e47,
    0x3fef199bdd85529c,
    0x3fef3720dcef9069,
    0x3fef5818dcfba487,
    0x3fef7c97337b9b5f,
    0x3fefa4afa2a490da,
    0x3fefd0765b6e4540,
];

/// 0x1.8p52 / 32: adding it rounds to a multiple of 1/32 and leaves that
/// multiple's numerator in the low bits.
pub(crate) const EXP2_SHIFT: f64 = f64::from_bits(0x42e8000000000000);

/// 2^r ≈ C₀r³ + C₁r² + C₂r + 1 for |r| ≤ 1/64.
pub(crate) const EXP2_POLY: [f64; 3] =
    [f64::from_bits(0x3fac6af84b912394), f64::from_bits(0x3fcebfce50fac4f3), f64::from_bits(0x3fe62e42ff0c52d6)];

/// y · log₂ x above this overflows f32.
pub(crate) const OVERFLOW: f64 = f64::from_bits(0x405ffffffffd1d57);

/// y · log₂ x below this is 0: the power would be subnormal (see `powf`).
pub(crate) const UNDERFLOW: f64 = -126.0;

/// `powf`'s fast path: x positive, normal and finite; y finite and not
/// zero. Anything else, libm answers (those results are exact).
#[inline(always)]
pub(crate) fn takes_fast_path(x_bits: u32, y_bits: u32) -> bool {
    x_bits.wrapping_sub(0x0080_0000) < 0x7f80_0000 - 0x0080_0000 && (y_bits << 1).wrapping_sub(1) < 0xff00_0000 - 1
}

/// xʸ (see the module's comment). `f32::powf`'s special cases (a zero,
/// subnormal, negative, infinite or NaN base; a zero, infinite or NaN
/// exponent) are libm's own. A power below f32's smallest normal is 0, not
/// subnormal: a subnormal costs x86 a microcode assist of a hundred cycles
/// or more where it is made and again wherever it is used, and such powers
/// (the far tails of glossy lobes, cosⁿ for n in the hundreds) carry
/// nothing an image can hold.
#[inline]
pub fn powf(x: f32, y: f32) -> f32 {
    if !takes_fast_path(x.to_bits(), y.to_bits()) {
        return x.powf(y);
    }
    let y_log2_x = y as f64 * log2_of(x.to_bits());
    if y_log2_x > OVERFLOW {
        f32::INFINITY
    } else if y_log2_x < UNDERFLOW {
        0.0
    } else {
        exp2_of(y_log2_x)
    }
}

/// log₂ x for a positive normal x, from its bits: x = 2ᵏ z with z in the
/// table's range, log₂ x = k + log₂ c + log₂(z/c).
#[inline(always)]
fn log2_of(x_bits: u32) -> f64 {
    let from_offset = x_bits.wrapping_sub(LOG2_OFFSET);
    let index = (from_offset >> 19) as usize % 16;
    let top = from_offset & 0xff80_0000;
    let z = f32::from_bits(x_bits.wrapping_sub(top)) as f64;
    let k = (top as i32 >> 23) as f64;
    let [inv_c, log2_c] = LOG2_TABLE[index];
    let r = z * inv_c - 1.0;
    let y0 = log2_c + k;
    let a = LOG2_POLY;
    let r2 = r * r;
    let y = a[0] * r + a[1];
    let p = a[2] * r + a[3];
    let r4 = r2 * r2;
    let q = a[4] * r + y0;
    let q = p * r2 + q;
    y * r4 + q
}

/// 2ˣ rounded to f32, for x within [UNDERFLOW, OVERFLOW]: x = k/32 + r.
#[inline(always)]
fn exp2_of(x: f64) -> f32 {
    let shifted = x + EXP2_SHIFT;
    let k_bits = shifted.to_bits();
    let r = x - (shifted - EXP2_SHIFT);
    let scale = f64::from_bits(EXP2_TABLE[(k_bits % 32) as usize].wrapping_add(k_bits << 47));
    let c = EXP2_POLY;
    let z = c[0] * r + c[1];
    let r2 = r * r;
    let y = c[2] * r + 1.0;
    ((z * r2 + y) * scale) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64: the bits of a u32 at a time.
    fn bits(state: &mut u64) -> u32 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 32) as u32
    }

    /// The distance in ulps from `got` to the exact xʸ (in f64, whose own
    /// error is 2⁻²⁹ of an f32 ulp).
    fn ulps_from_exact(got: f32, x: f32, y: f32) -> f64 {
        let exact = (x as f64).powf(y as f64);
        let ulp = (exact.abs() as f32).to_bits();
        let spacing = (f32::from_bits(ulp + 1) - f32::from_bits(ulp)) as f64;
        (got as f64 - exact).abs() / spacing.max(f64::from(f32::from_bits(1)))
    }

    /// Within 0.82 ulp of xʸ across bases and exponents of every size the
    /// renderer meets and beyond: a wrong table entry or coefficient, or a
    /// step out of order, is several ulps off (or worse) over some interval.
    #[test]
    fn powers_are_within_an_ulp_of_f64s() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut worst = 0.0f64;
        for _ in 0..400_000 {
            let x = f32::from_bits(0x0080_0000 + bits(&mut state) % (0x7f80_0000 - 0x0080_0000));
            let unit = (bits(&mut state) >> 8) as f32 / (1 << 24) as f32;
            let y = match bits(&mut state) % 3 {
                0 => 2.0 * unit - 1.0,
                1 => 400.0 * unit - 100.0,
                _ => (bits(&mut state) % 10_000) as f32,
            };
            let got = powf(x, y);
            let exact = (x as f64).powf(y as f64);
            if exact >= f32::MAX as f64 * (1.0 + 2f64.powi(-25)) {
                assert_eq!(got, f32::INFINITY, "{x}^{y}");
                continue;
            }
            // Never subnormal: 0 below the smallest normal, by rounding at it
            assert!(got == 0.0 || got.is_normal(), "{x}^{y}: {got:e}");
            if exact < f32::MIN_POSITIVE as f64 {
                assert!(got == 0.0 || exact > f32::MIN_POSITIVE as f64 * (1.0 - 2f64.powi(-23)), "{x}^{y}: {got:e}");
                continue;
            }
            let ulps = ulps_from_exact(got, x, y);
            worst = worst.max(ulps);
            assert!(ulps < 0.82, "{x}^{y}: {got}, exact {exact}, {ulps} ulp");
        }
        // Near 1, where x - 1 carries the whole answer
        for i in 0..20_000 {
            let x = f32::from_bits(1.0f32.to_bits() - 10_000 + i);
            for y in [0.5, 3.0, 100.0, 1e4, -7.0] {
                let ulps = ulps_from_exact(powf(x, y), x, y);
                assert!(ulps < 0.82, "{x}^{y}: {ulps} ulp");
            }
        }
        // The measure sees rounding (a correctly rounded power reaches 0.5)
        assert!(worst > 0.45, "worst {worst} ulp");
    }

    /// Overflow to ∞ at f32's bound, and 0 below its smallest normal.
    #[test]
    fn results_beyond_f32_overflow_and_underflow() {
        assert_eq!(powf(2.0, 128.0), f32::INFINITY);
        assert!(ulps_from_exact(powf(2.0, 127.99), 2.0, 127.99) < 0.82);
        assert_eq!(powf(2.0, -126.0), f32::MIN_POSITIVE);
        assert_eq!(powf(2.0, -125.5), (2.0f64.powf(-125.5)) as f32);
        assert_eq!(powf(2.0, -126.001), 0.0);
        assert_eq!(powf(2.0, -149.0), 0.0);
        assert_eq!(powf(0.5, 140.0), 0.0);
        assert_eq!(powf(0.45, 120.0), 0.0);
        assert_eq!(powf(10.0, -50.0), 0.0);
        assert_eq!(powf(10.0, 50.0), f32::INFINITY);
    }

    /// Off the fast path the answer is libm's, bit for bit.
    #[test]
    fn special_cases_are_libms() {
        let bases = [0.0, -0.0, -2.5, -1.0, 1e-40, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 0.3, 1.0, 4.0];
        let exponents = [0.0, -0.0, 1.0, 3.0, -2.0, 0.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        for x in bases {
            for y in exponents {
                if !takes_fast_path(x.to_bits(), y.to_bits()) {
                    assert_eq!(powf(x, y).to_bits(), x.powf(y).to_bits(), "{x}^{y}");
                }
            }
        }
        assert!(!takes_fast_path(1e-40f32.to_bits(), 2.0f32.to_bits()));
        assert!(!takes_fast_path(3.0f32.to_bits(), (-0.0f32).to_bits()));
        assert!(takes_fast_path(f32::MIN_POSITIVE.to_bits(), f32::MIN_POSITIVE.to_bits()));
        assert!(takes_fast_path(f32::MAX.to_bits(), (-f32::MAX).to_bits()));
    }
}
