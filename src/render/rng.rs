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

impl Sampler {
    /// The stream for one sample of one pixel (or one photon path: any pair of
    /// indices that names a unit of work).
    #[inline]
    pub fn new(index: u64, sample: u64, seed: u64) -> Self {
        let state = mix64(
            seed ^ mix64(index.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ mix64(sample.wrapping_add(0x632b_e59b_d9b4_e019))),
        );
        Self { state }
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

    /// Uniform in [0, 1): 24 random bits, so 1.0 is never returned.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }
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
}
