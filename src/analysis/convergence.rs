//! Error against time: one point per pass, and what the benchmark reads off
//! the curve (error at a time, time to reach an error, log–log slope).

use super::metrics::ErrorEstimate;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergencePoint {
    pub seconds: f64,
    pub samples_per_pixel: u32,
    pub rays: u64,
    /// relMSE against the reference, its noise taken out.
    pub error: ErrorEstimate,
    /// FLIP is costlier: measured at roughly log-spaced times only.
    pub flip: Option<f64>,
}

#[derive(Clone, Debug, Default)]
pub struct ConvergenceLog {
    pub points: Vec<ConvergencePoint>,
}

impl ConvergenceLog {
    pub fn push(&mut self, point: ConvergencePoint) {
        self.points.push(point);
    }

    /// relMSE of the last point at or before `seconds`.
    pub fn error_at(&self, seconds: f64) -> Option<f64> {
        self.points.iter().take_while(|p| p.seconds <= seconds).last().map(|p| p.error.rel_mse)
    }

    /// The first time relMSE fell to `threshold` or below.
    pub fn time_to_reach(&self, threshold: f64) -> Option<f64> {
        self.points.iter().find(|p| p.error.rel_mse <= threshold).map(|p| p.seconds)
    }

    /// Least-squares slope of log error against log time over the second
    /// half of the run (the asymptotic regime): −1 for an unbiased Monte
    /// Carlo estimator, flattening toward 0 where bias dominates.
    pub fn loglog_slope(&self) -> Option<f64> {
        let usable: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.seconds > 0.0 && p.error.rel_mse > 0.0)
            .map(|p| (p.seconds.ln(), p.error.rel_mse.ln()))
            .collect();
        let end = usable.last()?.0;
        let start = usable.first()?.0;
        let tail: Vec<(f64, f64)> = usable.into_iter().filter(|(t, _)| *t >= (start + end) * 0.5).collect();
        if tail.len() < 3 {
            return None;
        }
        let n = tail.len() as f64;
        let (mx, my) = (tail.iter().map(|p| p.0).sum::<f64>() / n, tail.iter().map(|p| p.1).sum::<f64>() / n);
        let sxx: f64 = tail.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = tail.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        (sxx > 0.0).then(|| sxy / sxx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_error_time_and_slope_off_a_known_curve() {
        let mut log = ConvergenceLog::default();
        for i in 1..=64 {
            let seconds = i as f64 * 0.25;
            let error = ErrorEstimate { rel_mse: 0.1 / seconds, standard_error: 0.0, noise_floor: None };
            log.push(ConvergencePoint { seconds, samples_per_pixel: i, rays: 0, error, flip: None });
        }
        assert!((log.loglog_slope().unwrap() + 1.0).abs() < 1e-9);
        assert_eq!(log.error_at(1.0), Some(0.1));
        assert_eq!(log.time_to_reach(0.01), Some(10.0));
        assert_eq!(log.time_to_reach(1e-6), None);
        assert_eq!(log.error_at(0.1), None);
    }
}
