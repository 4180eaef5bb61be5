//! Arithmetic written once for one number and for many: the math the
//! renderer shares (frames, ray offsets, the sphere solve, warps, Fresnel,
//! MIS weights) is generic over `Real`, and the scalar code and the
//! eight-lane path tracer instantiate the same functions. A lane therefore
//! computes bit for bit what the scalar code computes: the operations, their
//! order and their NaN rules are the same (min and max are `a < b ? a : b`
//! and `a > b ? a : b`, as MINPS and MAXPS are; branches are selects).

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{BVec4A, Vec3, Vec4};

use super::pow;

/// Which lanes a comparison held in.
pub trait Mask: Copy {
    fn and(self, other: Self) -> Self;
    fn or(self, other: Self) -> Self;
    fn and_not(self, other: Self) -> Self;
    fn xor(self, other: Self) -> Self;
}

/// One f32, or several side by side.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f32, Output = Self>
    + Sub<f32, Output = Self>
    + Mul<f32, Output = Self>
    + Div<f32, Output = Self>
{
    type Mask: Mask;
    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `self < other ? self : other`.
    fn min(self, other: Self) -> Self;
    /// `self > other ? self : other`.
    fn max(self, other: Self) -> Self;
    fn copysign(self, sign: Self) -> Self;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// Unordered: true where either is NaN.
    fn ne(self, other: Self) -> Self::Mask;
    fn is_finite(self) -> Self::Mask;
    /// `pow::powf`, lane by lane.
    fn powf(self, exponent: Self) -> Self;
    /// `a` where `mask` holds, `b` elsewhere.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// The spacing of floats in `self`'s binade, 23 bits below its exponent
    /// (0 for zero and subnormals).
    fn binade_ulp(self) -> Self;
    /// Whether the float's bits have any of `bits` set.
    fn bits_set(self, bits: u32) -> Self::Mask;
}

impl Mask for bool {
    #[inline(always)]
    fn and(self, other: bool) -> bool {
        self & other
    }
    #[inline(always)]
    fn or(self, other: bool) -> bool {
        self | other
    }
    #[inline(always)]
    fn and_not(self, other: bool) -> bool {
        self & !other
    }
    #[inline(always)]
    fn xor(self, other: bool) -> bool {
        self ^ other
    }
}

impl Real for f32 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn min(self, other: f32) -> f32 {
        if self < other {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    fn max(self, other: f32) -> f32 {
        if self > other {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    fn copysign(self, sign: f32) -> f32 {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, other: f32) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: f32) -> bool {
        self <= other
    }
    #[inline(always)]
    fn gt(self, other: f32) -> bool {
        self > other
    }
    #[inline(always)]
    fn ge(self, other: f32) -> bool {
        self >= other
    }
    #[inline(always)]
    fn eq(self, other: f32) -> bool {
        self == other
    }
    #[inline(always)]
    fn ne(self, other: f32) -> bool {
        self != other
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn powf(self, exponent: f32) -> f32 {
        pow::powf(self, exponent)
    }
    #[inline(always)]
    fn select(mask: bool, a: f32, b: f32) -> f32 {
        if mask {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn binade_ulp(self) -> f32 {
        f32::from_bits((self.to_bits() & 0x7f80_0000).saturating_sub(23 << 23))
    }
    #[inline(always)]
    fn bits_set(self, bits: u32) -> bool {
        self.to_bits() & bits != 0
    }
}

/// Four lanes (glam's SSE `Vec4`): four spheres against one ray.
impl Mask for BVec4A {
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        self & other
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        self | other
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        self & !other
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        self ^ other
    }
}

impl Real for Vec4 {
    type Mask = BVec4A;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        Vec4::splat(v)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }
    /// MINPS and MAXPS on x86-64; lane by lane with the same rule elsewhere.
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Vec4::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Vec4::max(self, other)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        Vec4::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> BVec4A {
        self.cmplt(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> BVec4A {
        self.cmple(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> BVec4A {
        self.cmpgt(other)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> BVec4A {
        self.cmpge(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> BVec4A {
        self.cmpeq(other)
    }
    #[inline(always)]
    fn ne(self, other: Self) -> BVec4A {
        self.cmpne(other)
    }
    #[inline(always)]
    fn is_finite(self) -> BVec4A {
        self.is_finite_mask()
    }
    #[inline(always)]
    fn powf(self, exponent: Self) -> Self {
        Vec4::new(
            pow::powf(self.x, exponent.x),
            pow::powf(self.y, exponent.y),
            pow::powf(self.z, exponent.z),
            pow::powf(self.w, exponent.w),
        )
    }
    #[inline(always)]
    fn select(mask: BVec4A, a: Self, b: Self) -> Self {
        Vec4::select(mask, a, b)
    }
    #[inline(always)]
    fn binade_ulp(self) -> Self {
        Vec4::from_array(self.to_array().map(Real::binade_ulp))
    }
    #[inline(always)]
    fn bits_set(self, bits: u32) -> BVec4A {
        let [a, b, c, d] = self.to_array().map(|v| v.bits_set(bits));
        BVec4A::new(a, b, c, d)
    }
}

/// A 3-vector of `R`: eight of them side by side when `R` is eight lanes.
/// Its arithmetic is glam's `Vec3`'s, operation for operation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<R> {
    pub x: R,
    pub y: R,
    pub z: R,
}

impl<R: Real> V3<R> {
    #[inline(always)]
    pub fn new(x: R, y: R, z: R) -> Self {
        V3 { x, y, z }
    }

    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3 { x: R::splat(v.x), y: R::splat(v.y), z: R::splat(v.z) }
    }

    #[inline(always)]
    pub fn dot(self, o: Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    pub fn length_squared(self) -> R {
        self.dot(self)
    }

    #[inline(always)]
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }

    /// glam's `normalize`: times the reciprocal of the length.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * (R::splat(1.0) / self.length())
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        V3 { x: self.x.abs(), y: self.y.abs(), z: self.z.abs() }
    }

    /// glam's `max_element`: `max(max(x, y), z)`.
    #[inline(always)]
    pub fn max_element(self) -> R {
        self.x.max(self.y).max(self.z)
    }

    #[inline(always)]
    pub fn element_sum(self) -> R {
        self.x + self.y + self.z
    }

    /// `a` where `mask` holds, `b` elsewhere.
    #[inline(always)]
    pub fn select(mask: R::Mask, a: Self, b: Self) -> Self {
        V3 { x: R::select(mask, a.x, b.x), y: R::select(mask, a.y, b.y), z: R::select(mask, a.z, b.z) }
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        V3 { x: v.x, y: v.y, z: v.z }
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl<R: Real> Add for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl<R: Real> Sub for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

/// Component by component (colours).
impl<R: Real> Mul for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
}

impl<R: Real> Mul<R> for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: R) -> Self {
        V3 { x: self.x * s, y: self.y * s, z: self.z * s }
    }
}

impl<R: Real> Div<R> for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: R) -> Self {
        V3 { x: self.x / s, y: self.y / s, z: self.z / s }
    }
}

impl<R: Real> Neg for V3<R> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3 { x: -self.x, y: -self.y, z: -self.z }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The f32 instance is glam's arithmetic, bit for bit, NaN rules too.
    #[test]
    fn the_scalar_instance_computes_what_glam_does() {
        let values = [0.0f32, -0.0, 1.5, -2.25, 1e-40, 3e38, f32::INFINITY, f32::NAN, 0.1];
        for &a in &values {
            for &b in &values {
                for &c in &values {
                    let (v, w) = (Vec3::new(a, b, c), Vec3::new(c, a, b));
                    let (gv, gw): (V3<f32>, V3<f32>) = (v.into(), w.into());
                    let same = |x: f32, y: f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
                    assert!(same(gv.dot(gw), v.dot(w)), "dot {v} {w}");
                    assert!(same(gv.length(), v.length()));
                    assert!(same(gv.max_element(), v.max_element()), "max_element {v}");
                    assert!(same(gv.element_sum(), v.element_sum()));
                    let (n, m) = (Vec3::from(gv.normalize()), v.normalize());
                    assert!(same(n.x, m.x) && same(n.y, m.y) && same(n.z, m.z), "normalize {v}");
                }
            }
        }
        assert_eq!(Real::max(f32::NAN, 0.0), 0.0, "as MAXPS: the second operand");
        assert!(Real::max(0.0, f32::NAN).is_nan());
        assert_eq!(1.0f32.binade_ulp(), f32::EPSILON);
    }
}
