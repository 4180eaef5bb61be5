//! Deterministic random numbers: every sample's stream is derived from
//! (pixel, sample index, seed) alone, so an image does not depend on thread
//! count or tile order, and disjoint sample ranges can be merged later.

use glam::Vec2;

#[derive(Clone, Debug)]
pub struct Sampler {
    state: u64,
}

#[inline(always)]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// What a pass's (sample index, seed) put into its streams, mixed once: a
/// tile's camera rays then cost one mix each.
#[derive(Clone, Copy, Debug)]
pub struct PassStreams {
    key: u64,
}

impl PassStreams {
    #[inline]
    pub fn new(sample: u64, seed: u64) -> Self {
        Self { key: mix64(seed ^ mix64(sample.wrapping_add(0x632b_e59b_d9b4_e019))) }
    }

    /// The stream of unit `index` (a pixel, a photon path) in this pass.
    #[inline]
    pub fn sampler(self, index: u64) -> Sampler {
        Sampler { state: mix64(index.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ self.key) }
    }
}

impl Sampler {
    /// The stream for one sample of one pixel (or one photon path: any pair of
    /// indices that names a unit of work).
    #[inline]
    pub fn new(index: u64, sample: u64, seed: u64) -> Self {
        PassStreams::new(sample, seed).sampler(index)
    }

    /// splitmix64: one add and a mix per number, statistically solid.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = Self::step(self.state);
        mix64(self.state)
    }

    /// The state after one draw (for streams kept in SIMD lanes).
    #[inline(always)]
    pub(crate) fn step(state: u64) -> u64 {
        state.wrapping_add(0x9e37_79b9_7f4a_7c15)
    }

    pub(crate) fn state(&self) -> u64 {
        self.state
    }

    /// The stream at `state`, as `state` gave it (for streams that drew
    /// in SIMD lanes).
    pub(crate) fn from_state(state: u64) -> Self {
        Sampler { state }
    }

    /// Uniform in [0, 1): 24 random bits, so 1.0 is never returned.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        unit_from_24_bits(self.next_u64() >> 40)
    }

    /// Two uniforms from one draw: its top 24 bits and the 24 below them
    /// (a draw is 64 well-mixed bits; the mix is what costs).
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let bits = self.next_u64();
        Vec2::new(unit_from_24_bits(bits >> 40), unit_from_24_bits((bits >> 16) & 0xff_ffff))
    }
}

/// 24 random bits as a float in [0, 1).
#[inline(always)]
pub(crate) fn unit_from_24_bits(bits: u64) -> f32 {
    // Exact through i32, which converts in one instruction
    (bits as i32) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_stream_and_neighbours_differ() {
        let mut a = Sampler::new(7, 3, 42);
        let mut b = Sampler::new(7, 3, 42);
        let mut c = Sampler::new(7, 4, 42);
        let mut d = Sampler::new(8, 3, 42);
        let xa: Vec<u64> = (0..8).map(|_| a.next_u64()).collect();
        assert_eq!(xa, (0..8).map(|_| b.next_u64()).collect::<Vec<_>>());
        assert_ne!(xa, (0..8).map(|_| c.next_u64()).collect::<Vec<_>>());
        assert_ne!(xa, (0..8).map(|_| d.next_u64()).collect::<Vec<_>>());
    }

    #[test]
    fn uniform_floats_have_the_right_mean_and_stay_below_one() {
        let mut s = Sampler::new(1, 2, 3);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = s.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.005);
    }

    /// The pair from one draw: each uniform, and the two uncorrelated (the
    /// covariance of two independent uniforms is 0, its estimate's standard
    /// error here 2.6e-4).
    #[test]
    fn pairs_are_uniform_and_uncorrelated() {
        let mut s = Sampler::new(4, 5, 6);
        let n = 100_000;
        let (mut sx, mut sy, mut sxy) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            let u = s.next_2d();
            assert!((0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y));
            (sx, sy, sxy) = (sx + u.x as f64, sy + u.y as f64, sxy + (u.x * u.y) as f64);
        }
        let (mx, my) = (sx / n as f64, sy / n as f64);
        assert!((mx - 0.5).abs() < 0.005 && (my - 0.5).abs() < 0.005, "means {mx} {my}");
        let covariance = sxy / n as f64 - mx * my;
        assert!(covariance.abs() < 1.5e-3, "covariance {covariance}");
    }
}
