//! Eight f32 lanes side by side, for tracing eight paths at once. Every
//! operation is the scalar one applied lane by lane, in the scalar code's
//! order and without fused multiply–adds, so a lane computes bit for bit what
//! the scalar code computes.
//!
//! On x86-64 the lanes are AVX registers operated on by intrinsics (`avx`):
//! left to LLVM, arrays of eight were split and re-packed differently after
//! every unrelated edit of the tracer, swinging its speed by a fifth. They
//! exist only where AVX2 does (`supported`). Elsewhere they are arrays
//! (`portable`), which the tests also hold the intrinsics to.

use std::ops::{Add, Div, Mul, Sub};

use glam::Vec3;

use crate::geometry::real::{Mask, Real, V3};
use crate::render::world::rng::{mix64, unit_from_24_bits, Sampler};

pub const LANES: usize = 8;

/// `[f(0), …, f(7)]`, always inlined: a helper left out of line would be
/// compiled without AVX2, and every intrinsic in it would become a call.
#[inline(always)]
pub fn each<T>(mut f: impl FnMut(usize) -> T) -> [T; LANES] {
    [f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)]
}

/// Whether this CPU runs the lanes.
pub fn supported() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    return true;
}

#[cfg(target_arch = "x86_64")]
mod avx;
mod column;
// On x86-64 only the tests build these, to hold the intrinsics to them
#[cfg(any(test, not(target_arch = "x86_64")))]
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
mod portable;

#[cfg(target_arch = "x86_64")]
pub use avx::{Count8, Index8, F8, M8};
pub use column::{Column, Column3};
#[cfg(not(target_arch = "x86_64"))]
pub use portable::{Count8, Index8, F8, M8};

// What both kinds of lanes share, written once over their primitives

impl F8 {
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        F8::from_array(each(f))
    }

    #[inline(always)]
    pub fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }

    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: f32) {
        let mut lanes = self.to_array();
        lanes[i] = v;
        *self = F8::from_array(lanes);
    }
}

macro_rules! scalar_op {
    ($trait:ident, $method:ident) => {
        impl $trait<f32> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: f32) -> F8 {
                self.$method(F8::splat(other))
            }
        }
        impl $trait<F8> for f32 {
            type Output = F8;
            #[inline(always)]
            fn $method(self, other: F8) -> F8 {
                F8::splat(self).$method(other)
            }
        }
    };
}
scalar_op!(Add, add);
scalar_op!(Sub, sub);
scalar_op!(Mul, mul);
scalar_op!(Div, div);

impl M8 {
    /// Lane i set where bit i is.
    #[inline(always)]
    pub fn from_bits(bits: u32) -> Self {
        M8::from_fn(|i| bits >> i & 1 != 0)
    }

    #[inline(always)]
    pub fn test(self, lane: usize) -> bool {
        self.bits() >> lane & 1 != 0
    }

    /// The lanes set, in order: one mask read, then only those lanes.
    #[inline(always)]
    pub fn lanes(self) -> impl Iterator<Item = usize> {
        let mut bits = self.bits();
        std::iter::from_fn(move || {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits.wrapping_sub(1);
            (lane < LANES).then_some(lane)
        })
    }

    #[inline(always)]
    pub fn set(&mut self, lane: usize, value: bool) {
        let lanes = self.to_array();
        *self = M8::from_fn(|i| if i == lane { value } else { lanes[i] != 0 });
    }

    #[inline(always)]
    pub fn count(self) -> u64 {
        self.bits().count_ones() as u64
    }

    #[inline(always)]
    pub fn select_v(self, a: V8, b: V8) -> V8 {
        V8 { x: self.select(a.x, b.x), y: self.select(a.y, b.y), z: self.select(a.z, b.z) }
    }
}

/// Eight 3-vectors (points, directions or colours), as glam computes them.
pub type V8 = V3<F8>;

/// What the lanes share with the scalar code: the math of `geometry::real`.
impl Mask for M8 {
    #[inline(always)]
    fn and(self, other: M8) -> M8 {
        M8::and(self, other)
    }
    #[inline(always)]
    fn or(self, other: M8) -> M8 {
        M8::or(self, other)
    }
    #[inline(always)]
    fn and_not(self, other: M8) -> M8 {
        M8::and_not(self, other)
    }
    #[inline(always)]
    fn xor(self, other: M8) -> M8 {
        M8::xor(self, other)
    }
}

impl Real for F8 {
    type Mask = M8;
    #[inline(always)]
    fn splat(v: f32) -> F8 {
        F8::splat(v)
    }
    #[inline(always)]
    fn sqrt(self) -> F8 {
        F8::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> F8 {
        F8::abs(self)
    }
    #[inline(always)]
    fn min(self, other: F8) -> F8 {
        F8::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: F8) -> F8 {
        F8::max(self, other)
    }
    #[inline(always)]
    fn copysign(self, sign: F8) -> F8 {
        F8::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, other: F8) -> M8 {
        F8::lt(self, other)
    }
    #[inline(always)]
    fn le(self, other: F8) -> M8 {
        F8::le(self, other)
    }
    #[inline(always)]
    fn gt(self, other: F8) -> M8 {
        F8::gt(self, other)
    }
    #[inline(always)]
    fn ge(self, other: F8) -> M8 {
        F8::ge(self, other)
    }
    #[inline(always)]
    fn eq(self, other: F8) -> M8 {
        F8::eq(self, other)
    }
    #[inline(always)]
    fn ne(self, other: F8) -> M8 {
        F8::ne(self, other)
    }
    #[inline(always)]
    fn is_finite(self) -> M8 {
        F8::is_finite(self)
    }
    #[inline(always)]
    fn powf(self, exponent: F8) -> F8 {
        F8::powf(self, exponent)
    }
    #[inline(always)]
    fn select(mask: M8, a: F8, b: F8) -> F8 {
        mask.select(a, b)
    }
    #[inline(always)]
    fn binade_ulp(self) -> F8 {
        F8::binade_ulp(self)
    }
    #[inline(always)]
    fn bits_set(self, bits: u32) -> M8 {
        F8::bits_set(self, bits)
    }
}

impl V3<F8> {
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> Vec3) -> Self {
        let v: [Vec3; LANES] = each(f);
        V3 { x: F8::from_fn(|i| v[i].x), y: F8::from_fn(|i| v[i].y), z: F8::from_fn(|i| v[i].z) }
    }

    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.lane(i), self.y.lane(i), self.z.lane(i))
    }

    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        self.x.set_lane(i, v.x);
        self.y.set_lane(i, v.y);
        self.z.set_lane(i, v.z);
    }

    /// Any component differs from zero (`v != Vec3::ZERO`).
    #[inline(always)]
    pub fn nonzero(self) -> M8 {
        let zero = F8::splat(0.0);
        self.x.ne(zero).or(self.y.ne(zero)).or(self.z.ne(zero))
    }
}

/// Eight `Sampler` streams; each lane advances only where asked.
///
/// Each lane's next draw is mixed ahead, as soon as the one before it is
/// taken: a draw then hands out bits worked out long before, and the mix's
/// latency (two 64-bit multiplies emulated by six) stays off the path's
/// chain of dependent work.
#[derive(Clone, Copy, Debug)]
pub struct Rng8 {
    state: [u64; LANES],
    /// What lane i's next draw returns: `mix64(step(state[i]))`.
    ahead: [u64; LANES],
}

impl Rng8 {
    pub fn new() -> Self {
        Self::from_states([0; LANES])
    }

    /// Streams from their `Sampler` states.
    #[inline(always)]
    pub fn from_states(state: [u64; LANES]) -> Self {
        Rng8 { state, ahead: each(|i| mix64(Sampler::step(state[i]))) }
    }

    #[inline(always)]
    pub fn states(&self) -> [u64; LANES] {
        self.state
    }

    /// Each lane's next draw, mixed (for `start`).
    #[inline(always)]
    pub fn ahead(&self) -> [u64; LANES] {
        self.ahead
    }

    /// Lane `lane` takes up the stream at `state`, whose next draw `ahead`
    /// is (`Rng8::ahead` of the streams it comes from).
    #[inline(always)]
    pub fn start(&mut self, lane: usize, state: u64, ahead: u64) {
        self.state[lane] = state;
        self.ahead[lane] = ahead;
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
        unit_pairs(self.next_bits(mask))
    }

    /// What `next_2d` will return, without drawing it.
    #[inline(always)]
    pub fn peek_2d(&self) -> (F8, F8) {
        unit_pairs(self.ahead)
    }

    /// `Sampler::next_u64` in the lanes of `mask`; the draw after it mixed
    /// ahead (from the stepped state, so not waiting for the mask).
    #[inline(always)]
    fn next_bits(&mut self, mask: M8) -> [u64; LANES] {
        let bits = self.ahead;
        let advanced: [u64; LANES] = each(|i| Sampler::step(self.state[i]));
        let after: [u64; LANES] = each(|i| mix64(Sampler::step(advanced[i])));
        let mask = mask.to_array();
        self.state = each(|i| if mask[i] != 0 { advanced[i] } else { self.state[i] });
        self.ahead = each(|i| if mask[i] != 0 { after[i] } else { self.ahead[i] });
        bits
    }
}

/// `Sampler::next_2d`'s two uniforms of each lane's draw.
#[inline(always)]
fn unit_pairs(bits: [u64; LANES]) -> (F8, F8) {
    let u0 = F8::from_fn(|i| unit_from_24_bits(bits[i] >> 40));
    (u0, F8::from_fn(|i| unit_from_24_bits((bits[i] >> 16) & 0xff_ffff)))
}

impl Default for Rng8 {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pow;

    #[test]
    fn lanes_draw_the_scalar_streams_and_hold_where_masked() {
        assert!(supported(), "the lanes need AVX2");
        let mut samplers: Vec<Sampler> = (0..LANES as u64).map(|i| Sampler::new(i, 3, 9)).collect();
        let mut rng = Rng8::from_states(std::array::from_fn(|i| samplers[i].state()));
        for round in 0..20 {
            // Lanes advance on alternate rounds, by lane parity
            let mask = M8::from_fn(|i| (i + round) % 2 == 0);
            let drawn = rng.next_f32(mask);
            let pair = rng.next_2d(mask);
            for (lane, s) in samplers.iter_mut().enumerate() {
                if mask.test(lane) {
                    assert_eq!(drawn.lane(lane).to_bits(), s.next_f32().to_bits());
                    let u = s.next_2d();
                    assert_eq!(
                        (pair.0.lane(lane).to_bits(), pair.1.lane(lane).to_bits()),
                        (u.x.to_bits(), u.y.to_bits())
                    );
                }
            }
            // Every fifth round one lane takes up a new stream, the others
            // keeping theirs
            if round % 5 == 4 {
                let lane = round % LANES;
                samplers[lane] = Sampler::new(100 + round as u64, 3, 9);
                let taken = Rng8::from_states([samplers[lane].state(); LANES]);
                rng.start(lane, taken.states()[0], taken.ahead()[0]);
            }
        }
        assert_eq!(rng.states(), std::array::from_fn(|i| samplers[i].state()));
    }

    /// `Real::powf` in the lanes is `pow::powf` lane by lane, bit for bit:
    /// the bases and exponents a glossy lobe or a spot light meets (cosines
    /// in [0, 1], exponents 0 to 10⁴), bases and exponents of every size
    /// (overflow and underflow), and every special case (NaN, zeros,
    /// negatives, infinities, subnormals), mixed in one vector, and vectors
    /// with no lane on the fast path.
    #[test]
    fn powers_are_the_scalar_ones() {
        let mut rng = Sampler::new(4, 5, 6);
        let special = [f32::NAN, 0.0, -0.0, -2.5, 1.0, f32::INFINITY, -f32::INFINITY, 1e-40];
        let exponents = [0.0, -0.0, 1.0, 0.5, 40.0, -3.0, f32::INFINITY, f32::NAN];
        for case in 0..20_000 {
            let base = |i: usize, rng: &mut Sampler| match (case + i) % 5 {
                0 => special[(case / 5 + i) % special.len()],
                1 => f32::from_bits(rng.next_u64() as u32),
                _ => rng.next_f32(),
            };
            let exponent = |i: usize, rng: &mut Sampler| match (case + 3 * i) % 6 {
                0 => exponents[(case / 6 + i) % exponents.len()],
                1 => f32::from_bits(rng.next_u64() as u32),
                2 => (rng.next_f32() - 0.5) * 400.0,
                _ => rng.next_f32() * 1e4,
            };
            let x: [f32; LANES] = std::array::from_fn(|i| base(i, &mut rng));
            let mut e: [f32; LANES] = std::array::from_fn(|i| exponent(i, &mut rng));
            // Every lane x⁰ or 0ʸ now and then (a point light's lanes), where
            // no lane takes the fast path
            if case % 7 == 0 {
                e = std::array::from_fn(|i| if x[i] == 0.0 && i % 2 == 0 { 2.0 } else { 0.0 });
            }
            let got = Real::powf(F8::from_array(x), F8::from_array(e)).to_array();
            for i in 0..LANES {
                let expected = pow::powf(x[i], e[i]);
                assert_eq!(got[i].to_bits(), expected.to_bits(), "{}^{}: {} against {}", x[i], e[i], got[i], expected);
            }
        }
    }

    /// `lanes` gives the set lanes of every mask, each once, in order.
    #[test]
    fn a_masks_lanes_are_its_set_bits_in_order() {
        for bits in 0..1u32 << LANES {
            let lanes: Vec<usize> = M8::from_bits(bits).lanes().collect();
            let expected: Vec<usize> = (0..LANES).filter(|&i| bits >> i & 1 != 0).collect();
            assert_eq!(lanes, expected, "{bits:#b}");
        }
    }

    #[test]
    fn select_and_compare_follow_the_scalar_rules() {
        assert!(supported(), "the lanes need AVX2");
        let a = F8::from_array([0.0, -0.0, 1.0, f32::NAN, -2.0, 3.0, f32::INFINITY, 5.0]);
        let b = F8::splat(0.5);
        let m = a.lt(b);
        assert_eq!(m.to_array(), [-1, -1, 0, 0, -1, 0, 0, 0]);
        assert_eq!((m.count(), m.bits()), (3, 0b1_0011));
        let s = m.select(a, b).to_array();
        assert_eq!((s[4], s[3]), (-2.0, 0.5));
        assert!(s[1].is_sign_negative());
        assert_eq!(a.min(b).lane(3), 0.5, "min takes the second operand on NaN");
        assert_eq!(a.max(b).lane(3), 0.5);
        let v = V8::from_fn(|i| Vec3::new(i as f32, 1.0, -2.0));
        assert_eq!(v.lane(3), Vec3::new(3.0, 1.0, -2.0));
        assert_eq!(v.dot(v).lane(3), Vec3::new(3.0, 1.0, -2.0).length_squared());
    }

    /// The AVX lanes against the arrays, which apply Rust's scalar
    /// operations lane by lane: every operation, bit for bit, on the
    /// awkward values (signed zeros, NaN, infinities, subnormals, huge and
    /// tiny numbers) paired every way, and on random ones.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_lanes_compute_what_the_scalar_operations_do() {
        use super::portable as p;
        assert!(supported(), "the lanes need AVX2");
        let awkward = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            -f32::INFINITY,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(3),
            f32::MAX,
            -f32::MAX,
            1e-30,
            3.0e7,
            16_777_217.0,
            12_582_915.0,
            0.95,
            2.0,
            3.0,
            4.0,
        ];
        let mut rng = Sampler::new(1, 2, 3);
        let mut values: Vec<f32> = awkward.to_vec();
        values.extend((0..200).map(|_| f32::from_bits(rng.next_u64() as u32)));
        values.extend((0..200).map(|_| (rng.next_f32() - 0.5) * 1e3));
        let n = values.len();
        let bits = |v: [f32; LANES]| v.map(f32::to_bits);
        for start in 0..n {
            // Eight consecutive values against eight taken with a stride
            let a: [f32; LANES] = std::array::from_fn(|i| values[(start + i) % n]);
            let b: [f32; LANES] = std::array::from_fn(|i| values[(start * 7 + i * 13 + 5) % n]);
            let (fa, fb) = (F8::from_array(a), F8::from_array(b));
            let (pa, pb) = (p::F8::from_array(a), p::F8::from_array(b));
            let same = |got: F8, want: p::F8, op: &str| {
                assert_eq!(bits(got.to_array()), bits(want.to_array()), "{op} of {a:?} and {b:?}");
            };
            same(fa + fb, pa + pb, "+");
            same(fa - fb, pa - pb, "-");
            same(fa * fb, pa * pb, "*");
            same(fa / fb, pa / pb, "/");
            same(-fa, -pa, "neg");
            same(fa.min(fb), pa.min(pb), "min");
            same(fa.max(fb), pa.max(pb), "max");
            same(fa.sqrt(), pa.sqrt(), "sqrt");
            same(fa.abs(), pa.abs(), "abs");
            same(fa.copysign(fb), pa.copysign(pb), "copysign");
            same(fa.abs().binade_ulp(), pa.abs().binade_ulp(), "binade_ulp");
            same(fa.powf(fb), pa.powf(pb), "powf");
            same(fa.abs().powf(fb), pa.abs().powf(pb), "powf of |a|");
            // Truncation is only asked of numbers within i32's range
            let whole = fa.min(F8::splat(2e9)).max(F8::splat(-2e9));
            let p_whole = pa.min(p::F8::splat(2e9)).max(p::F8::splat(-2e9));
            assert_eq!(whole.truncate(), p_whole.truncate(), "truncate {a:?}");
            // Indices of every sign and size read the same members: from
            // sixteen by permutes, from the whole list by a gather
            let (index, p_index) = (whole.to_index(), p_whole.to_index());
            assert_eq!(index.to_array(), p_index.to_array());
            same(F8::permuted(fa, fb, index), p::F8::permuted(pa, pb, p_index), "permuted");
            same(F8::picked(fa, index), p::F8::picked(pa, p_index), "picked");
            let small = F8::from_fn(|i| (a[i].to_bits() % 24) as f32 - 2.0).to_index();
            let p_small = p::F8::from_array(std::array::from_fn(|i| (a[i].to_bits() % 24) as f32 - 2.0)).to_index();
            same(F8::permuted(fa, fb, small), p::F8::permuted(pa, pb, p_small), "permuted");
            same(F8::gathered(&values, small), p::F8::gathered(&values, p_small), "gathered");
            same(F8::gathered(&values, index), p::F8::gathered(&values, p_index), "gathered");
            let masks = [
                (fa.lt(fb), pa.lt(pb)),
                (fa.le(fb), pa.le(pb)),
                (fa.gt(fb), pa.gt(pb)),
                (fa.ge(fb), pa.ge(pb)),
                (fa.eq(fb), pa.eq(pb)),
                (fa.ne(fb), pa.ne(pb)),
                (fa.is_finite(), pa.is_finite()),
                (fa.bits_set(3), pa.bits_set(3)),
                (fa.bits_set(2), pa.bits_set(2)),
            ];
            for (k, (m, pm)) in masks.iter().enumerate() {
                assert_eq!(m.to_array(), pm.to_array(), "comparison {k} of {a:?} and {b:?}");
                assert_eq!((m.bits(), m.any()), (pm.bits(), pm.any()));
                same(m.select(fa, fb), pm.select(pa, pb), "select");
                let (m2, pm2) = masks[(k + 1) % masks.len()];
                for (got, want) in [
                    (m.and(m2), pm.and(pm2)),
                    (m.or(m2), pm.or(pm2)),
                    (m.xor(m2), pm.xor(pm2)),
                    (m.and_not(m2), pm.and_not(pm2)),
                    (!*m, !*pm),
                    (m.select_mask(m2, !m2), pm.select_mask(pm2, !pm2)),
                ] {
                    assert_eq!(got.to_array(), want.to_array());
                }
            }
            // One lane alone (none past the last), and every lane alike
            let lane = start % (LANES + 2);
            assert_eq!(M8::only(lane).to_array(), p::M8::only(lane).to_array(), "only lane {lane}");
            assert_eq!(M8::only(lane).bits(), if lane < LANES { 1 << lane } else { 0 }, "only lane {lane}");
            let value = a[0] < b[0];
            assert_eq!(M8::splat(value).to_array(), p::M8::splat(value).to_array());
            assert_eq!(M8::splat(value).bits(), if value { 0xff } else { 0 });
            let depths: [u32; LANES] = std::array::from_fn(|i| (a[i].to_bits() >> 28) + i as u32);
            let (count, p_count) = (Count8::from_array(depths), p::Count8::from_array(depths));
            for bound in [0, 3, 9, 20, u32::MAX] {
                assert_eq!(count.ge(bound).to_array(), p_count.ge(bound).to_array());
            }
            let (m, pm) = (fa.lt(fb), pa.lt(pb));
            let first = (start % 7) as i32 - 2;
            let pair = Index8::of_pair(first, m).to_array();
            assert_eq!(pair, p::Index8::of_pair(first, pm).to_array());
            assert_eq!(pair, m.to_array().map(|set| first + (set != 0) as i32), "of_pair");
            assert_eq!(count.count_in(m).to_array(), p_count.count_in(pm).to_array());
            assert_eq!(count.reset(m).to_array(), p_count.reset(pm).to_array());
            assert_eq!(M8::from_bits(m.bits()), m);
        }
    }
}
