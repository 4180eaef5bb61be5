//! The lanes as AVX registers, one intrinsic an operation: LLVM neither
//! splits them into scalars nor re-packs them, so the code of the lanes is
//! what is written here, whatever else changes in the function around it.
//!
//! The invariant that makes this sound: these values exist only on CPUs
//! with AVX2. `lane_world` builds lanes only inside its AVX2 entry point,
//! entered after `is_x86_feature_detected!("avx2")`; other CPUs render with
//! the scalar tracer. The tests that use the lanes directly check the CPU
//! first, and `lanes` is private to the crate, so nothing outside can
//! make one.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Not, Sub};

use crate::geometry::pow;
use crate::render::world::lanes::LANES;

#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct F8(__m256);

/// A lane mask: all bits set where true, none where false.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct M8(__m256);

/// Eight counters (path depths).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct Count8(__m256i);

/// Eight indices into a `Column`.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub struct Index8(__m256i);

// SAFETY (every `unsafe` below): AVX2 is present (the module's invariant);
// the stores write whole local arrays.

impl F8 {
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        F8(unsafe { _mm256_set1_ps(v) })
    }

    /// Built in registers: eight scalar stores then one wide load would
    /// stall (the load cannot be forwarded from several stores).
    #[inline(always)]
    pub fn from_array(v: [f32; LANES]) -> Self {
        F8(unsafe { _mm256_setr_ps(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]) })
    }

    /// Eight consecutive values in memory, in one load.
    #[inline(always)]
    pub fn load(v: &[f32; LANES]) -> Self {
        F8(unsafe { _mm256_loadu_ps(v.as_ptr()) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [f32; LANES] {
        let mut out = [0.0; LANES];
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }

    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, other: F8) -> M8 {
        M8(unsafe { _mm256_cmp_ps::<PREDICATE>(self.0, other.0) })
    }

    #[inline(always)]
    pub fn lt(self, other: F8) -> M8 {
        self.compare::<_CMP_LT_OQ>(other)
    }

    #[inline(always)]
    pub fn le(self, other: F8) -> M8 {
        self.compare::<_CMP_LE_OQ>(other)
    }

    #[inline(always)]
    pub fn gt(self, other: F8) -> M8 {
        self.compare::<_CMP_GT_OQ>(other)
    }

    #[inline(always)]
    pub fn ge(self, other: F8) -> M8 {
        self.compare::<_CMP_GE_OQ>(other)
    }

    #[inline(always)]
    pub fn eq(self, other: F8) -> M8 {
        self.compare::<_CMP_EQ_OQ>(other)
    }

    /// True where either is NaN, as `!=` is.
    #[inline(always)]
    pub fn ne(self, other: F8) -> M8 {
        self.compare::<_CMP_NEQ_UQ>(other)
    }

    #[inline(always)]
    pub fn is_finite(self) -> M8 {
        self.abs().lt(F8::splat(f32::INFINITY))
    }

    /// MINPS: `self < other ? self : other`, glam's `min`; and `f32::min`
    /// against a number never NaN, as LLVM compiles the scalar tracer's.
    #[inline(always)]
    pub fn min(self, other: F8) -> Self {
        F8(unsafe { _mm256_min_ps(self.0, other.0) })
    }

    /// MAXPS: `self > other ? self : other`, glam's `max`; and `f32::max`
    /// against a number never NaN (`x.max(0.0)`), as LLVM compiles it.
    #[inline(always)]
    pub fn max(self, other: F8) -> Self {
        F8(unsafe { _mm256_max_ps(self.0, other.0) })
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        F8(unsafe { _mm256_sqrt_ps(self.0) })
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }

    #[inline(always)]
    pub fn copysign(self, sign: F8) -> Self {
        F8(unsafe {
            let sign_bit = _mm256_set1_ps(-0.0);
            _mm256_or_ps(_mm256_andnot_ps(sign_bit, self.0), _mm256_and_ps(sign_bit, sign.0))
        })
    }

    /// `f32::from_bits((bits & 0x7f80_0000).saturating_sub(23 << 23))`:
    /// the spacing of floats in a non-negative lane's binade (`ulp`).
    #[inline(always)]
    pub fn binade_ulp(self) -> Self {
        F8(unsafe {
            let exponent = _mm256_and_si256(_mm256_castps_si256(self.0), _mm256_set1_epi32(0x7f80_0000));
            // A saturating subtraction: both are non-negative as i32
            let shift = _mm256_set1_epi32(23 << 23);
            _mm256_castsi256_ps(_mm256_sub_epi32(_mm256_max_epi32(exponent, shift), shift))
        })
    }

    /// `as i32` for lanes within i32's range (whole numbers: indices).
    #[inline(always)]
    pub fn truncate(self) -> [i32; LANES] {
        let mut out = [0; LANES];
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), _mm256_cvttps_epi32(self.0)) };
        out
    }

    /// `truncate`, kept in a register to index `Column`s with.
    #[inline(always)]
    pub fn to_index(self) -> Index8 {
        Index8(unsafe { _mm256_cvttps_epi32(self.0) })
    }

    /// `table[index]` lane by lane for indices in 0..8: one permute
    /// (other indices read by their low three bits).
    #[inline(always)]
    pub fn picked(table: F8, index: Index8) -> F8 {
        F8(unsafe { _mm256_permutevar8x32_ps(table.0, index.0) })
    }

    /// `table[index]` lane by lane for indices in 0..16, `low` holding the
    /// table's first eight values and `high` the rest: two permutes and a
    /// blend (other indices give one of the sixteen).
    #[inline(always)]
    pub fn permuted(low: F8, high: F8, index: Index8) -> F8 {
        F8(unsafe {
            let from_low = _mm256_permutevar8x32_ps(low.0, index.0);
            let from_high = _mm256_permutevar8x32_ps(high.0, index.0);
            let in_high = _mm256_cmpgt_epi32(index.0, _mm256_set1_epi32(7));
            _mm256_blendv_ps(from_low, from_high, _mm256_castsi256_ps(in_high))
        })
    }

    /// `values[index]` lane by lane, an index beyond the last (or
    /// negative) reading the last: one hardware gather.
    #[inline(always)]
    pub fn gathered(values: &[f32], index: Index8) -> F8 {
        let Some(last) = values.len().checked_sub(1) else { return F8::splat(0.0) };
        let last = last.min(i32::MAX as usize) as i32;
        // SAFETY: as unsigned, a negative index exceeds `last`, so every
        // lane reads within `values`
        F8(unsafe {
            let clamped = _mm256_min_epu32(index.0, _mm256_set1_epi32(last));
            _mm256_i32gather_ps::<4>(values.as_ptr(), clamped)
        })
    }

    /// `pow::powf` lane by lane, four lanes at a time in f64 with its
    /// operations in its order, unfused, so the bits are the scalar
    /// function's. Lanes off its fast path take it one by one, but x⁰ = 1
    /// and 0ʸ = 0 (y > 0), which glossy paths meet all the time (Lambert
    /// lanes, directions outside the lobe), are answered here.
    #[inline(always)]
    pub fn powf(self, exponent: F8) -> F8 {
        unsafe {
            let x_bits = _mm256_castps_si256(self.0);
            let y_abs_bits = _mm256_castps_si256(exponent.abs().0);
            // `pow::takes_fast_path`: x positive, normal and finite; y finite, not 0
            let x_normal = _mm256_and_si256(
                _mm256_cmpgt_epi32(x_bits, _mm256_set1_epi32(0x007f_ffff)),
                _mm256_cmpgt_epi32(_mm256_set1_epi32(0x7f80_0000), x_bits),
            );
            let y_zero = _mm256_cmpeq_epi32(y_abs_bits, _mm256_setzero_si256());
            let y_finite = _mm256_cmpgt_epi32(_mm256_set1_epi32(0x7f80_0000), y_abs_bits);
            let fast = M8(_mm256_castsi256_ps(_mm256_andnot_si256(y_zero, _mm256_and_si256(x_normal, y_finite))));
            let zero_base = M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(x_bits, _mm256_setzero_si256())))
                .and(exponent.gt(F8::splat(0.0)));
            // A signalling NaN's x⁰ is NaN in libm
            let one = M8(_mm256_castsi256_ps(y_zero)).and(self.eq(self));
            let pending = !fast.or(one).or(zero_base);
            let settled = one.select(F8::splat(1.0), F8::splat(0.0));
            // Only where a lane takes the fast path: the f64 evaluation of
            // what the other lanes hold (a point light's x⁰ in every lane)
            // would spend its time in subnormal assists
            let power = if fast.any() {
                // log₂ x's table index, exponent and reduced mantissa (`pow::log2_of`)
                let from_offset = _mm256_sub_epi32(x_bits, _mm256_set1_epi32(pow::LOG2_OFFSET as i32));
                let entry = _mm256_slli_epi32::<1>(_mm256_and_si256(
                    _mm256_srli_epi32::<19>(from_offset),
                    _mm256_set1_epi32(15),
                ));
                let top = _mm256_and_si256(from_offset, _mm256_set1_epi32(0xff80_0000u32 as i32));
                let z = _mm256_castsi256_ps(_mm256_sub_epi32(x_bits, top));
                let k = _mm256_srai_epi32::<23>(top);
                let low = power_half(
                    _mm256_castps256_ps128(z),
                    _mm256_castsi256_si128(k),
                    _mm256_castsi256_si128(entry),
                    _mm256_castps256_ps128(exponent.0),
                );
                let high = power_half(
                    _mm256_extractf128_ps::<1>(z),
                    _mm256_extracti128_si256::<1>(k),
                    _mm256_extracti128_si256::<1>(entry),
                    _mm256_extractf128_ps::<1>(exponent.0),
                );
                fast.select(F8(_mm256_set_m128(high, low)), settled)
            } else {
                settled
            };
            if !pending.any() {
                return power;
            }
            let (x, y, mut out) = (self.to_array(), exponent.to_array(), power.to_array());
            for i in pending.lanes() {
                out[i] = pow::powf(x[i], y[i]);
            }
            F8::from_array(out)
        }
    }

    /// Lanes whose bit pattern has any of `bits` set.
    #[inline(always)]
    pub fn bits_set(self, bits: u32) -> M8 {
        M8(unsafe {
            let masked = _mm256_and_si256(_mm256_castps_si256(self.0), _mm256_set1_epi32(bits as i32));
            let clear = _mm256_cmpeq_epi32(masked, _mm256_setzero_si256());
            _mm256_castsi256_ps(_mm256_xor_si256(clear, _mm256_set1_epi32(-1)))
        })
    }
}

/// Four lanes of `F8::powf`'s fast path from the parts of x and y: the
/// reduced mantissa `z`, exponent `k` and table `entry` of x, and y.
/// A function, not a closure: a closure is left out of line, without AVX2.
/// SAFETY: the gathers read within the tables, `entry` being 2·(0…15) and
/// the exp2 index masked to 0…31.
#[inline(always)]
unsafe fn power_half(z: __m128, k: __m128i, entry: __m128i, y: __m128) -> __m128 {
    let table = pow::LOG2_TABLE.as_ptr().cast::<f64>();
    let inv_c = _mm256_i32gather_pd::<8>(table, entry);
    let log2_c = _mm256_i32gather_pd::<8>(table, _mm_add_epi32(entry, _mm_set1_epi32(1)));
    let r = _mm256_sub_pd(_mm256_mul_pd(_mm256_cvtps_pd(z), inv_c), _mm256_set1_pd(1.0));
    let y0 = _mm256_add_pd(log2_c, _mm256_cvtepi32_pd(k));
    let [a0, a1, a2, a3, a4] = pow::LOG2_POLY;
    let r2 = _mm256_mul_pd(r, r);
    let p1 = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(a0), r), _mm256_set1_pd(a1));
    let p2 = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(a2), r), _mm256_set1_pd(a3));
    let r4 = _mm256_mul_pd(r2, r2);
    let q = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(a4), r), y0);
    let q = _mm256_add_pd(_mm256_mul_pd(p2, r2), q);
    let log2_x = _mm256_add_pd(_mm256_mul_pd(p1, r4), q);
    let y_log2_x = _mm256_mul_pd(_mm256_cvtps_pd(y), log2_x);
    // 2^(y log₂ x) (`pow::exp2_of`), then f32's bounds
    let shift = _mm256_set1_pd(pow::EXP2_SHIFT);
    let shifted = _mm256_add_pd(y_log2_x, shift);
    let k_bits = _mm256_castpd_si256(shifted);
    let r = _mm256_sub_pd(y_log2_x, _mm256_sub_pd(shifted, shift));
    let index = _mm256_and_si256(k_bits, _mm256_set1_epi64x(31));
    let entry = _mm256_i64gather_epi64::<8>(pow::EXP2_TABLE.as_ptr().cast::<i64>(), index);
    let scale = _mm256_castsi256_pd(_mm256_add_epi64(entry, _mm256_slli_epi64::<47>(k_bits)));
    let [c0, c1, c2] = pow::EXP2_POLY;
    let p = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(c0), r), _mm256_set1_pd(c1));
    let r2 = _mm256_mul_pd(r, r);
    let q = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(c2), r), _mm256_set1_pd(1.0));
    let power = _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(p, r2), q), scale);
    let over = _mm256_cmp_pd::<_CMP_GT_OQ>(y_log2_x, _mm256_set1_pd(pow::OVERFLOW));
    let under = _mm256_cmp_pd::<_CMP_LT_OQ>(y_log2_x, _mm256_set1_pd(pow::UNDERFLOW));
    let power = _mm256_blendv_pd(power, _mm256_set1_pd(f64::INFINITY), over);
    _mm256_cvtpd_ps(_mm256_blendv_pd(power, _mm256_setzero_pd(), under))
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for F8 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: F8) -> F8 {
                F8(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    };
}
lane_op!(Add, add, _mm256_add_ps);
lane_op!(Sub, sub, _mm256_sub_ps);
lane_op!(Mul, mul, _mm256_mul_ps);
lane_op!(Div, div, _mm256_div_ps);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl PartialEq for F8 {
    /// Lane by lane, as `[f32; 8]` compares.
    fn eq(&self, other: &F8) -> bool {
        self.to_array() == other.to_array()
    }
}

impl fmt::Debug for F8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "F8({:?})", self.to_array())
    }
}

impl M8 {
    // SAFETY: any bit pattern is a valid __m256
    pub const NONE: M8 = M8(unsafe { std::mem::transmute::<[i32; LANES], __m256>([0; LANES]) });
    pub const ALL: M8 = M8(unsafe { std::mem::transmute::<[i32; LANES], __m256>([-1; LANES]) });

    /// Only lane `lane` (none for a lane past the last).
    #[inline(always)]
    pub fn only(lane: usize) -> Self {
        let lane = lane.min(LANES) as i32;
        M8(unsafe {
            let index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(index, _mm256_set1_epi32(lane)))
        })
    }

    /// Every lane `value`.
    #[inline(always)]
    pub fn splat(value: bool) -> Self {
        M8(unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(-(value as i32))) })
    }

    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        let v: [i32; LANES] = crate::render::world::lanes::each(|i| -(f(i) as i32));
        M8(unsafe { _mm256_castsi256_ps(_mm256_setr_epi32(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7])) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [i32; LANES] {
        let mut out = [0; LANES];
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), _mm256_castps_si256(self.0)) };
        out
    }

    #[inline(always)]
    pub fn bits(self) -> u32 {
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        unsafe { _mm256_testz_ps(self.0, self.0) == 0 }
    }

    #[inline(always)]
    pub fn and(self, other: M8) -> M8 {
        M8(unsafe { _mm256_and_ps(self.0, other.0) })
    }

    #[inline(always)]
    pub fn or(self, other: M8) -> M8 {
        M8(unsafe { _mm256_or_ps(self.0, other.0) })
    }

    #[inline(always)]
    pub fn xor(self, other: M8) -> M8 {
        M8(unsafe { _mm256_xor_ps(self.0, other.0) })
    }

    #[inline(always)]
    pub fn and_not(self, other: M8) -> M8 {
        M8(unsafe { _mm256_andnot_ps(other.0, self.0) })
    }

    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        F8(unsafe { _mm256_blendv_ps(b.0, a.0, self.0) })
    }

    #[inline(always)]
    pub fn select_mask(self, a: M8, b: M8) -> M8 {
        M8(unsafe { _mm256_blendv_ps(b.0, a.0, self.0) })
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        self.xor(M8::ALL)
    }
}

impl PartialEq for M8 {
    fn eq(&self, other: &M8) -> bool {
        self.to_array() == other.to_array()
    }
}

impl Eq for M8 {}

impl fmt::Debug for M8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "M8({:?})", self.to_array())
    }
}

impl Count8 {
    // SAFETY: any bit pattern is a valid __m256i
    pub const ZERO: Count8 = Count8(unsafe { std::mem::transmute::<[u32; LANES], __m256i>([0; LANES]) });

    #[cfg(test)]
    pub fn from_array(v: [u32; LANES]) -> Self {
        let v = v.map(|c| c as i32);
        Count8(unsafe { _mm256_setr_epi32(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [u32; LANES] {
        let mut out = [0; LANES];
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), self.0) };
        out
    }

    /// Counts stay far below 2³¹: a signed comparison.
    #[inline(always)]
    pub fn ge(self, bound: u32) -> M8 {
        let bound = bound.min(i32::MAX as u32) as i32;
        M8(unsafe {
            let below = _mm256_cmpgt_epi32(_mm256_set1_epi32(bound), self.0);
            _mm256_castsi256_ps(_mm256_xor_si256(below, _mm256_set1_epi32(-1)))
        })
    }

    #[inline(always)]
    pub fn count_in(self, mask: M8) -> Count8 {
        Count8(unsafe { _mm256_sub_epi32(self.0, _mm256_castps_si256(mask.0)) })
    }

    #[inline(always)]
    pub fn reset(self, mask: M8) -> Count8 {
        Count8(unsafe { _mm256_andnot_si256(_mm256_castps_si256(mask.0), self.0) })
    }
}

impl Index8 {
    /// `first` in the lanes `second` leaves clear, `first + 1` where it is
    /// set (a set lane is −1 as an integer).
    #[inline(always)]
    pub fn of_pair(first: i32, second: M8) -> Self {
        Index8(unsafe { _mm256_sub_epi32(_mm256_set1_epi32(first), _mm256_castps_si256(second.0)) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [i32; LANES] {
        let mut out = [0; LANES];
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), self.0) };
        out
    }
}

impl fmt::Debug for Index8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Index8({:?})", self.to_array())
    }
}

impl fmt::Debug for Count8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Count8({:?})", self.to_array())
    }
}
