//! Walker's alias method (Vose's construction): one of n items drawn in
//! proportion to its weight in constant time, whatever n, from one uniform
//! number, which is handed back rescaled to [0, 1) for the next choice.

/// A discrete distribution over `0..n` drawn in O(1).
#[derive(Clone, Debug)]
pub struct AliasTable {
    /// Per column: the chance of keeping the column's own item, and the
    /// item taken otherwise.
    columns: Vec<(f32, u32)>,
    /// Each item's probability (its weight over the total).
    probabilities: Vec<f32>,
}

impl AliasTable {
    /// For `weights` (none negative, none NaN); `None` when they are all zero
    /// or there are none.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let total: f64 = weights.iter().sum();
        // NaN fails every comparison: such weights are refused too
        let usable = total.is_finite() && total > 0.0 && weights.iter().all(|w| *w >= 0.0);
        if !usable {
            return None;
        }
        let n = weights.len();
        // Each weight scaled so that the mean is 1: columns under 1 are
        // topped up from columns over it
        let mut scaled: Vec<f64> = weights.iter().map(|w| w / total * n as f64).collect();
        let mut columns = vec![(1.0f32, 0u32); n];
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            columns[s] = (scaled[s] as f32, l as u32);
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left is 1 but for rounding: kept whole
        for i in small.into_iter().chain(large) {
            columns[i] = (1.0, i as u32);
        }
        let probabilities = weights.iter().map(|w| (w / total) as f32).collect();
        Some(Self { columns, probabilities })
    }

    /// The probability of drawing item `i`.
    pub fn probability(&self, i: usize) -> f32 {
        self.probabilities.get(i).copied().unwrap_or(0.0)
    }

    /// The item `u` ∈ [0, 1) draws, and `u` rescaled to [0, 1) within
    /// the part of its column that chose it.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.columns.len();
        let scaled = u * n as f32;
        let column = (scaled as usize).min(n - 1);
        let within = (scaled - column as f32).clamp(0.0, 1.0);
        let (keep, alias) = self.columns[column];
        if within < keep {
            (column, (within / keep).min(ONE_BELOW))
        } else {
            (alias as usize, ((within - keep) / (1.0 - keep)).clamp(0.0, ONE_BELOW))
        }
    }
}

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// Drawn a million times, each item comes up in proportion to its
    /// weight: every count within 5 standard deviations of its binomial
    /// mean, zero weights never; the rescaled number stays uniform (its
    /// mean ½ within 5 standard errors) and in [0, 1).
    #[test]
    fn items_come_up_in_proportion_to_their_weights() {
        let weights = [3.0, 0.0, 1.0, 10.0, 0.5, 0.5, 7.25, 0.0, 2.0, 1e-3];
        let table = AliasTable::new(&weights).expect("weights");
        let total: f64 = weights.iter().sum();
        let mut s = Sampler::new(1, 2, 3);
        let n = 1_000_000;
        let mut counts = [0usize; 10];
        let mut rescaled = 0.0f64;
        for _ in 0..n {
            let (i, u) = table.sample(s.next_f32());
            assert!((0.0..1.0).contains(&u), "{u}");
            counts[i] += 1;
            rescaled += u as f64;
        }
        for (i, (&count, &w)) in counts.iter().zip(&weights).enumerate() {
            let p = w / total;
            assert!((table.probability(i) as f64 - p).abs() < 1e-6);
            let sigma = (n as f64 * p * (1.0 - p)).sqrt();
            assert!((count as f64 - n as f64 * p).abs() <= 5.0 * sigma, "item {i}: {count} against {}", n as f64 * p);
            if w == 0.0 {
                assert_eq!(count, 0, "item {i} has no weight");
            }
        }
        let mean = rescaled / n as f64;
        assert!((mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / n as f64).sqrt(), "rescaled mean {mean}");
    }

    #[test]
    fn no_weight_no_table() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, f64::NAN]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0, 2.0]).is_none());
        let one = AliasTable::new(&[0.0, 4.0]).expect("one item weighs");
        assert_eq!(one.sample(0.3).0, 1);
        assert_eq!(one.sample(0.99).0, 1);
    }
}
