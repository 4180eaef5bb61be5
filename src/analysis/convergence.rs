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

    /// relMSE of the last point at or before `seconds`; none if the run
    /// ended before `seconds` (a 2-s run has no error at 4 s, whatever it
    /// had when it stopped).
    pub fn error_at(&self, seconds: f64) -> Option<f64> {
        if self.points.last().is_none_or(|last| last.seconds < seconds) {
            return None;
        }
        self.points.iter().take_while(|p| p.seconds <= seconds).last().map(|p| p.error.rel_mse)
    }

    /// The first time relMSE fell to `threshold` or below.
    pub fn time_to_reach(&self, threshold: f64) -> Option<f64> {
        self.points.iter().find(|p| p.error.rel_mse <= threshold).map(|p| p.seconds)
    }

    /// The first time after which relMSE stays at `threshold` or below to
    /// the end of the run. A noisy curve can dip below once early on: to
    /// say when one algorithm has another's error, `time_to_reach` would
    /// answer too soon.
    pub fn time_to_stay_within(&self, threshold: f64) -> Option<f64> {
        let above = |p: &ConvergencePoint| p.error.rel_mse.is_nan() || p.error.rel_mse > threshold;
        match self.points.iter().rposition(above) {
            None => self.points.first().map(|p| p.seconds),
            Some(above) => self.points.get(above + 1).map(|p| p.seconds),
        }
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
        assert_eq!(log.time_to_stay_within(0.01), Some(10.0));
        // The curve ends at 16 s
        assert_eq!(log.error_at(16.0), Some(0.1 / 16.0));
        assert_eq!(log.error_at(16.5), None, "no error after the run ended");
    }

    /// A curve that dips to 0.1 at 1 s, rises, comes back at 4 s and
    /// stays there but for a NaN at 6 s: reached at 1 s, stayed at from 7 s.
    #[test]
    fn staying_within_waits_for_the_last_rise() {
        let log = ConvergenceLog {
            points: [0.5, 0.09, 0.2, 0.15, 0.1, 0.08, f64::NAN, 0.05]
                .iter()
                .enumerate()
                .map(|(i, &rel_mse)| ConvergencePoint {
                    seconds: i as f64,
                    samples_per_pixel: i as u32,
                    rays: 0,
                    error: ErrorEstimate { rel_mse, standard_error: 0.0, noise_floor: None },
                    flip: None,
                })
                .collect(),
        };
        assert_eq!(log.time_to_reach(0.1), Some(1.0));
        assert_eq!(log.time_to_stay_within(0.1), Some(7.0), "a NaN is not within");
        let before_nan = ConvergenceLog { points: log.points[..6].to_vec() };
        assert_eq!(before_nan.time_to_stay_within(0.1), Some(4.0));
        assert_eq!(before_nan.time_to_stay_within(0.5), Some(0.0));
        assert_eq!(log.time_to_stay_within(0.01), None);
        assert_eq!(ConvergenceLog::default().time_to_stay_within(1.0), None);
    }
}
