//! Eight f32 lanes side by side, for tracing eight paths at once. Every
//! operation is the scalar one applied lane by lane, in the scalar code's
//! order and without fused multiply–adds, so a lane computes bit for bit what
//! the scalar code computes; inlined into a loop, LLVM turns each into one
//! SIMD instruction (one AVX2 instruction where `path_lanes` dispatches to
//! AVX2, two SSE ones otherwise).

use std::array::from_fn;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::Vec3;

use super::rng::{mix64, unit_from_24_bits, Sampler};

pub const LANES: usize = 8;

#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F8(pub [f32; LANES]);

/// A lane mask: −1 (all bits) where true, 0 where false.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M8(pub [i32; LANES]);

impl F8 {
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        F8([v; LANES])
    }

    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        F8(from_fn(f))
    }

    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        F8(from_fn(|i| f(self.0[i])))
    }

    #[inline(always)]
    pub fn zip(self, other: F8, f: impl Fn(f32, f32) -> f32) -> Self {
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
    pub fn is_finite(self) -> M8 {
        M8::from_fn(|i| self.0[i].is_finite())
    }

    #[inline(always)]
    pub fn ne(self, other: F8) -> M8 {
        self.compare(other, |a, b| a != b)
    }

    /// `f32::max` (a NaN operand yields the other).
    #[inline(always)]
    pub fn max(self, other: F8) -> Self {
        self.zip(other, f32::max)
    }

    /// `f32::min`.
    #[inline(always)]
    pub fn min(self, other: F8) -> Self {
        self.zip(other, f32::min)
    }

    /// glam's `Vec3::min`: `a < b ? a : b`.
    #[inline(always)]
    pub fn min_glam(self, other: F8) -> Self {
        self.zip(other, |a, b| if a < b { a } else { b })
    }

    /// glam's `Vec3::max`: `a > b ? a : b`.
    #[inline(always)]
    pub fn max_glam(self, other: F8) -> Self {
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
        impl $trait<f32> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: f32) -> F8 {
                self.map(|a| a $op other)
            }
        }
        impl $trait<F8> for f32 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: F8) -> F8 {
                other.map(|b| self $op b)
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

    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> bool) -> Self {
        M8(from_fn(|i| -(f(i) as i32)))
    }

    #[inline(always)]
    pub fn test(self, lane: usize) -> bool {
        self.0[lane] != 0
    }

    #[inline(always)]
    pub fn set(&mut self, lane: usize, value: bool) {
        self.0[lane] = -(value as i32);
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, b| a | b) != 0
    }

    #[inline(always)]
    pub fn count(self) -> u64 {
        self.0.iter().map(|&m| (m & 1) as u64).sum()
    }

    #[inline(always)]
    pub fn and(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] & other.0[i]))
    }

    #[inline(always)]
    pub fn or(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] | other.0[i]))
    }

    /// self ∧ ¬other.
    #[inline(always)]
    pub fn and_not(self, other: M8) -> M8 {
        M8(from_fn(|i| self.0[i] & !other.0[i]))
    }

    /// Per lane: `a` where set, `b` elsewhere.
    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        F8(from_fn(|i| f32::from_bits((self.0[i] as u32 & a.0[i].to_bits()) | (!self.0[i] as u32 & b.0[i].to_bits()))))
    }

    #[inline(always)]
    pub fn select_mask(self, a: M8, b: M8) -> M8 {
        M8(from_fn(|i| (self.0[i] & a.0[i]) | (!self.0[i] & b.0[i])))
    }

    #[inline(always)]
    pub fn select_v(self, a: V8, b: V8) -> V8 {
        V8 { x: self.select(a.x, b.x), y: self.select(a.y, b.y), z: self.select(a.z, b.z) }
    }
}

impl std::ops::Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(from_fn(|i| !self.0[i]))
    }
}

/// Eight counters (path depths).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct Count8(pub [u32; LANES]);

impl Count8 {
    #[inline(always)]
    pub fn ge(self, bound: u32) -> M8 {
        M8(from_fn(|i| -((self.0[i] >= bound) as i32)))
    }

    /// One more in the lanes of `mask`.
    #[inline(always)]
    pub fn count_in(self, mask: M8) -> Count8 {
        Count8(from_fn(|i| self.0[i].wrapping_sub(mask.0[i] as u32)))
    }
}

/// Eight 3-vectors (points, directions or colours), as glam computes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V8 {
    pub x: F8,
    pub y: F8,
    pub z: F8,
}

impl V8 {
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V8 { x: F8::splat(v.x), y: F8::splat(v.y), z: F8::splat(v.z) }
    }

    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> Vec3) -> Self {
        let v: [Vec3; LANES] = from_fn(f);
        V8 { x: F8::from_fn(|i| v[i].x), y: F8::from_fn(|i| v[i].y), z: F8::from_fn(|i| v[i].z) }
    }

    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        (self.x.0[i], self.y.0[i], self.z.0[i]) = (v.x, v.y, v.z);
    }

    #[inline(always)]
    pub fn dot(self, o: V8) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    pub fn length_squared(self) -> F8 {
        self.dot(self)
    }

    #[inline(always)]
    pub fn length(self) -> F8 {
        self.dot(self).sqrt()
    }

    /// glam's `normalize`: times the reciprocal of the length.
    #[inline(always)]
    pub fn normalize(self) -> V8 {
        self * (1.0 / self.length())
    }

    /// Component by component, as glam's `Vec3::min`.
    #[inline(always)]
    pub fn min(self, o: V8) -> V8 {
        V8 { x: self.x.min_glam(o.x), y: self.y.min_glam(o.y), z: self.z.min_glam(o.z) }
    }

    /// Component by component, as glam's `Vec3::max`.
    #[inline(always)]
    pub fn max(self, o: V8) -> V8 {
        V8 { x: self.x.max_glam(o.x), y: self.y.max_glam(o.y), z: self.z.max_glam(o.z) }
    }

    #[inline(always)]
    pub fn abs(self) -> V8 {
        V8 { x: self.x.abs(), y: self.y.abs(), z: self.z.abs() }
    }

    #[inline(always)]
    pub fn max_element(self) -> F8 {
        self.x.max_glam(self.y).max_glam(self.z)
    }

    #[inline(always)]
    pub fn element_sum(self) -> F8 {
        self.x + self.y + self.z
    }

    /// Any component differs from zero (`v != Vec3::ZERO`).
    #[inline(always)]
    pub fn nonzero(self) -> M8 {
        let zero = F8::splat(0.0);
        self.x.ne(zero).or(self.y.ne(zero)).or(self.z.ne(zero))
    }
}

impl Add for V8 {
    type Output = V8;
    #[inline(always)]
    fn add(self, o: V8) -> V8 {
        V8 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl Sub for V8 {
    type Output = V8;
    #[inline(always)]
    fn sub(self, o: V8) -> V8 {
        V8 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// Component by component (colours).
impl Mul for V8 {
    type Output = V8;
    #[inline(always)]
    fn mul(self, o: V8) -> V8 {
        V8 { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
}

impl Mul<F8> for V8 {
    type Output = V8;
    #[inline(always)]
    fn mul(self, s: F8) -> V8 {
        V8 { x: self.x * s, y: self.y * s, z: self.z * s }
    }
}

impl Div<F8> for V8 {
    type Output = V8;
    #[inline(always)]
    fn div(self, s: F8) -> V8 {
        V8 { x: self.x / s, y: self.y / s, z: self.z / s }
    }
}

impl Neg for V8 {
    type Output = V8;
    #[inline(always)]
    fn neg(self) -> V8 {
        V8 { x: -self.x, y: -self.y, z: -self.z }
    }
}

/// Eight `Sampler` streams; each lane advances only where asked.
#[derive(Clone, Copy, Debug)]
pub struct Rng8 {
    state: [u64; LANES],
}

impl Rng8 {
    pub fn new() -> Self {
        Rng8 { state: [0; LANES] }
    }

    /// Streams from their `Sampler` states.
    #[inline(always)]
    pub fn from_states(state: [u64; LANES]) -> Self {
        Rng8 { state }
    }

    #[inline(always)]
    pub fn states(&self) -> [u64; LANES] {
        self.state
    }

    #[inline(always)]
    pub fn set_lane(&mut self, lane: usize, state: u64) {
        self.state[lane] = state;
    }

    /// `Sampler::next_f32` in the lanes of `mask` (others: unchanged, value unused).
    #[inline(always)]
    pub fn next_f32(&mut self, mask: M8) -> F8 {
        let bits = self.next_bits(mask);
        F8::from_fn(|i| unit_from_24_bits(bits[i] >> 40))
    }

    /// `Sampler::next_2d` in the lanes of `mask`.
    #[inline(always)]
    pub fn next_2d(&mut self, mask: M8) -> (F8, F8) {
        let bits = self.next_bits(mask);
        let u0 = F8::from_fn(|i| unit_from_24_bits(bits[i] >> 40));
        (u0, F8::from_fn(|i| unit_from_24_bits((bits[i] >> 16) & 0xff_ffff)))
    }

    /// `Sampler::next_u64` in the lanes of `mask`.
    #[inline(always)]
    fn next_bits(&mut self, mask: M8) -> [u64; LANES] {
        let advanced: [u64; LANES] = from_fn(|i| Sampler::step(self.state[i]));
        self.state = from_fn(|i| if mask.0[i] != 0 { advanced[i] } else { self.state[i] });
        from_fn(|i| mix64(advanced[i]))
    }
}

impl Default for Rng8 {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_draw_the_scalar_streams_and_hold_where_masked() {
        let mut samplers: Vec<Sampler> = (0..LANES as u64).map(|i| Sampler::new(i, 3, 9)).collect();
        let mut rng = Rng8::from_states(std::array::from_fn(|i| samplers[i].state()));
        for round in 0..20 {
            // Lanes advance on alternate rounds, by lane parity
            let mask = M8::from_fn(|i| (i + round) % 2 == 0);
            let drawn = rng.next_f32(mask);
            let pair = rng.next_2d(mask);
            for (lane, s) in samplers.iter_mut().enumerate() {
                if mask.test(lane) {
                    assert_eq!(drawn.0[lane].to_bits(), s.next_f32().to_bits());
                    let u = s.next_2d();
                    assert_eq!((pair.0 .0[lane].to_bits(), pair.1 .0[lane].to_bits()), (u.x.to_bits(), u.y.to_bits()));
                }
            }
        }
    }

    #[test]
    fn select_and_compare_follow_the_scalar_rules() {
        let a = F8([0.0, -0.0, 1.0, f32::NAN, -2.0, 3.0, f32::INFINITY, 5.0]);
        let b = F8::splat(0.5);
        let m = a.lt(b);
        assert_eq!(m.0, [-1, -1, 0, 0, -1, 0, 0, 0]);
        assert_eq!(m.count(), 3);
        let s = m.select(a, b);
        assert_eq!(s.0[4], -2.0);
        assert_eq!(s.0[3], 0.5);
        assert!(s.0[1].is_sign_negative());
        assert_eq!(a.min_glam(b).0[3], 0.5, "glam's min takes the second operand on NaN");
        assert_eq!(a.max(b).0[3], 0.5);
        let v = V8::from_fn(|i| Vec3::new(i as f32, 1.0, -2.0));
        assert_eq!(v.lane(3), Vec3::new(3.0, 1.0, -2.0));
        assert_eq!(v.dot(v).0[3], Vec3::new(3.0, 1.0, -2.0).length_squared());
    }
}
