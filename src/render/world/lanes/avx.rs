//! The lanes as AVX registers, one intrinsic an operation: LLVM neither
//! splits them into scalars nor re-packs them, so the code of the lanes is
//! what is written here, whatever else changes in the function around it.
//!
//! The invariant that makes this sound: these values exist only on CPUs
//! with AVX2. `path_lanes` builds lanes only inside its AVX2 entry point,
//! entered after `is_x86_feature_detected!("avx2")`; other CPUs render with
//! the scalar tracer. The tests that use the lanes directly check the CPU
//! first, and `lanes` is private to the crate, so nothing outside can
//! make one.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Not, Sub};

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

impl fmt::Debug for Count8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Count8({:?})", self.to_array())
    }
}
