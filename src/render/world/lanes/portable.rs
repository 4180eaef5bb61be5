//! The lanes as arrays, operated on lane by lane: what CPUs without AVX2
//! run (LLVM vectorizes the loops where it can), and the reference the AVX2
//! lanes are tested against.

use std::ops::{Add, Div, Mul, Neg, Not, Sub};

use crate::geometry::pow;
use crate::render::world::lanes::{each as from_fn, LANES};

#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F8([f32; LANES]);

/// A lane mask: all bits set where true, none where false.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8([i32; LANES]);

/// Eight counters (path depths).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct Count8([u32; LANES]);

/// Eight indices into a `Column`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct Index8([i32; LANES]);

impl F8 {
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        F8([v; LANES])
    }

    #[inline(always)]
    pub fn from_array(v: [f32; LANES]) -> Self {
        F8(v)
    }

    #[inline(always)]
    pub fn load(v: &[f32; LANES]) -> Self {
        F8(*v)
    }

    #[inline(always)]
    pub fn to_array(self) -> [f32; LANES] {
        self.0
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        F8(from_fn(|i| f(self.0[i])))
    }

    #[inline(always)]
    fn zip(self, other: F8, f: impl Fn(f32, f32) -> f32) -> Self {
        F8(from_fn(|i| f(self.0[i], other.0[i])))
    }

    #[inline(always)]
    fn compare(self, other: F8, f: impl Fn(f32, f32) -> bool) -> M8 {
        M8(from_fn(|i| -(f(self.0[i], other.0[i]) as i32)))
    }

    #[inline(always)]
    pub fn lt(self, other: F8) -> M8 {
        self.compare(other, |a, b| a < b)
    }

    #[inline(always)]
    pub fn le(self, other: F8) -> M8 {
        self.compare(other, |a, b| a <= b)
    }

    #[inline(always)]
    pub fn gt(self, other: F8) -> M8 {
        self.compare(other, |a, b| a > b)
    }

    #[inline(always)]
    pub fn ge(self, other: F8) -> M8 {
        self.compare(other, |a, b| a >= b)
    }

    #[inline(always)]
    pub fn eq(self, other: F8) -> M8 {
        self.compare(other, |a, b| a == b)
    }

    #[inline(always)]
    pub fn ne(self, other: F8) -> M8 {
        self.compare(other, |a, b| a != b)
    }

    #[inline(always)]
    pub fn is_finite(self) -> M8 {
        M8(from_fn(|i| -(self.0[i].is_finite() as i32)))
    }

    #[inline(always)]
    pub fn min(self, other: F8) -> Self {
        self.zip(other, |a, b| if a < b { a } else { b })
    }

    #[inline(always)]
    pub fn max(self, other: F8) -> Self {
        self.zip(other, |a, b| if a > b { a } else { b })
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        self.map(f32::abs)
    }

    #[inline(always)]
    pub fn copysign(self, sign: F8) -> Self {
        self.zip(sign, f32::copysign)
    }

    /// `f32::from_bits((bits & 0x7f80_0000).saturating_sub(23 << 23))`:
    /// the spacing of floats in a non-negative lane's binade (`ulp`).
    #[inline(always)]
    pub fn binade_ulp(self) -> Self {
        self.map(|v| f32::from_bits((v.to_bits() & 0x7f80_0000).saturating_sub(23 << 23)))
    }

    /// `as i32` for lanes within i32's range (whole numbers: indices).
    #[inline(always)]
    pub fn truncate(self) -> [i32; LANES] {
        self.0.map(|v| v as i32)
    }

    /// `truncate`, kept to index `Column`s with.
    #[inline(always)]
    pub fn to_index(self) -> Index8 {
        Index8(self.truncate())
    }

    /// `table[index]` lane by lane for indices in 0..8 (other indices read
    /// by their low three bits, as the AVX2 permute reads them).
    #[inline(always)]
    pub fn picked(table: F8, index: Index8) -> F8 {
        F8(from_fn(|i| table.0[(index.0[i] & 7) as usize]))
    }

    /// `table[index]` lane by lane for indices in 0..16, `low` holding the
    /// table's first eight values and `high` the rest (other indices read
    /// as the AVX2 permutes read them).
    #[inline(always)]
    pub fn permuted(low: F8, high: F8, index: Index8) -> F8 {
        F8(from_fn(|i| {
            let k = index.0[i];
            let table = if k > 7 { high } else { low };
            table.0[(k & 7) as usize]
        }))
    }

    /// `values[index]` lane by lane, an index beyond the last (or
    /// negative) reading the last.
    #[inline(always)]
    pub fn gathered(values: &[f32], index: Index8) -> F8 {
        let Some(&last) = values.last() else { return F8::splat(0.0) };
        F8(from_fn(|i| usize::try_from(index.0[i]).ok().and_then(|k| values.get(k)).copied().unwrap_or(last)))
    }

    #[inline(always)]
    pub fn powf(self, exponent: F8) -> Self {
        self.zip(exponent, pow::powf)
    }

    /// Lanes whose bit pattern has any of `bits` set.
    #[inline(always)]
    pub fn bits_set(self, bits: u32) -> M8 {
        M8(from_fn(|i| -((self.0[i].to_bits() & bits != 0) as i32)))
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F8 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: F8) -> F8 {
                self.zip(other, |a, b| a $op b)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        self.map(|a| -a)
    }
}

impl M8 {
    pub const NONE: M8 = M8([0; LANES]);
    pub const ALL: M8 = M8([-1; LANES]);

    /// Only lane `lane` (none for a lane past the last).
    #[inline(always)]
    pub fn only(lane: usize) -> Self {
        M8(from_fn(|i| -((i == lane) as i32)))
    }

    /// Every lane `value`.
    #[inline(always)]
    pub fn splat(value: bool) -> Self {
        M8([-(value as i32); LANES])
    }

    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        M8(from_fn(|i| -(f(i) as i32)))
    }

    #[inline(always)]
    pub fn to_array(self) -> [i32; LANES] {
        self.0
    }

    #[inline(always)]
    pub fn bits(self) -> u32 {
        (0..LANES).fold(0, |bits, i| bits | ((self.0[i] as u32) >> 31) << i)
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, b| a | b) != 0
    }

    #[inline(always)]
    pub fn and(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] & other.0[i]))
    }

    #[inline(always)]
    pub fn or(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] | other.0[i]))
    }

    #[inline(always)]
    pub fn xor(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] ^ other.0[i]))
    }

    #[inline(always)]
    pub fn and_not(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] & !other.0[i]))
    }

    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        F8(from_fn(|i| f32::from_bits((self.0[i] as u32 & a.0[i].to_bits()) | (!self.0[i] as u32 & b.0[i].to_bits()))))
    }

    #[inline(always)]
    pub fn select_mask(self, a: M8, b: M8) -> M8 {
        M8(from_fn(|i| (self.0[i] & a.0[i]) | (!self.0[i] & b.0[i])))
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(from_fn(|i| !self.0[i]))
    }
}

impl Index8 {
    /// `first` in the lanes `second` leaves clear, `first + 1` where it is set.
    #[inline(always)]
    pub fn of_pair(first: i32, second: M8) -> Self {
        Index8(from_fn(|i| first.wrapping_sub(second.0[i])))
    }

    #[inline(always)]
    pub fn to_array(self) -> [i32; LANES] {
        self.0
    }
}

impl Count8 {
    pub const ZERO: Count8 = Count8([0; LANES]);

    // For the test against the intrinsics
    #[cfg(all(test, target_arch = "x86_64"))]
    pub fn to_array(self) -> [u32; LANES] {
        self.0
    }

    #[cfg(all(test, target_arch = "x86_64"))]
    pub fn from_array(v: [u32; LANES]) -> Self {
        Count8(v)
    }

    #[inline(always)]
    pub fn ge(self, bound: u32) -> M8 {
        M8(from_fn(|i| -((self.0[i] >= bound) as i32)))
    }

    #[inline(always)]
    pub fn count_in(self, mask: M8) -> Count8 {
        Count8(from_fn(|i| self.0[i].wrapping_sub(mask.0[i] as u32)))
    }

    #[inline(always)]
    pub fn reset(self, mask: M8) -> Count8 {
        Count8(from_fn(|i| self.0[i] & !mask.0[i] as u32))
    }
}
