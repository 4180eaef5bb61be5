//! The statistics the tests decide by: χ² goodness of fit with its p-value,
//! Student's t and the normal distribution's tails and quantiles (Numerical
//! Recipes' incomplete gamma and beta functions, in f64). Each test states
//! the false-alarm rate its threshold gives.
#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

use glam::Vec3;

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9: relative error < 1e-14).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x)Γ(1 − x) = π / sin(πx)
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let series = C[1..].iter().enumerate().fold(C[0], |sum, (i, c)| sum + c / (x + i as f64 + 1.0));
    0.5 * TAU.ln() + (x + 0.5) * t.ln() - t + series.ln()
}

/// The regularised upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // The series for P(a, x)
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * front).max(0.0)
    } else {
        // Lentz's continued fraction for Q(a, x)
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < tiny { tiny } else { d };
            c = b + an / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        front * h
    }
}

/// P(χ²_dof ≥ statistic).
pub fn chi_square_p_value(statistic: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, statistic / 2.0)
}

/// The regularised incomplete beta function I_x(a, b).
pub fn beta_i(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    // The continued fraction converges fast for x < (a + 1)/(a + b + 2)
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_fraction(b, a, 1.0 - x) / b
    }
}

fn beta_fraction(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    d = if d.abs() < tiny { tiny } else { d };
    d = 1.0 / d;
    let mut h = d;
    for m in 1..10_000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        for aa in [m * (b - m) * x / ((qam + m2) * (a + m2)), -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))] {
            d = 1.0 + aa * d;
            d = if d.abs() < tiny { tiny } else { d };
            c = 1.0 + aa / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// P(|T| ≥ t) for Student's t with `dof` degrees of freedom.
pub fn student_t_two_sided(t: f64, dof: f64) -> f64 {
    beta_i(dof / 2.0, 0.5, dof / (dof + t * t))
}

/// The t with P(|T| ≥ t) = p, by bisection.
pub fn student_t_quantile(p_two_sided: f64, dof: f64) -> f64 {
    bisect_tail(|t| student_t_two_sided(t, dof), p_two_sided)
}

/// P(|Z| ≥ z) for a standard normal Z.
pub fn normal_two_sided(z: f64) -> f64 {
    // erfc(z/√2) = Q(½, z²/2)
    gamma_q(0.5, z * z / 2.0)
}

/// The z with P(|Z| ≥ z) = p.
pub fn normal_quantile(p_two_sided: f64) -> f64 {
    bisect_tail(normal_two_sided, p_two_sided)
}

/// The point where a falling tail probability reaches `p`.
fn bisect_tail(tail: impl Fn(f64) -> f64, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1e3);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Šidák's per-test level for `tests` tests at family-wise level `alpha`.
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests as f64)
}

/// A χ² goodness-of-fit result.
#[derive(Clone, Copy, Debug)]
pub struct ChiSquare {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Pearson's χ² of `observed` against `expected` counts; bins expecting
/// fewer than 5 are pooled into one, as the test's approximation needs.
pub fn chi_square(observed: &[f64], expected: &[f64]) -> ChiSquare {
    let (mut statistic, mut bins, mut pooled_o, mut pooled_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(expected) {
        if *e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            statistic += (o - e).powi(2) / e;
            bins += 1;
        }
    }
    if pooled_e >= 5.0 {
        statistic += (pooled_o - pooled_e).powi(2) / pooled_e;
        bins += 1;
    } else if pooled_o > 0.0 && pooled_e == 0.0 {
        // Samples where the pdf says none can be
        statistic = f64::INFINITY;
    }
    let dof = bins.saturating_sub(1).max(1);
    ChiSquare { statistic, dof, p_value: chi_square_p_value(statistic, dof) }
}

/// 1 − cos θ of a unit direction about +z, without cancellation: a cone
/// of 1 − cos = 1e-5 is a hundred float steps of cos θ near 1, but its sine
/// is exact.
pub fn one_minus_cos(local: Vec3) -> f64 {
    let (x, y, z) = (local.x as f64, local.y as f64, local.z as f64);
    if z > 0.0 {
        (x * x + y * y) / (1.0 + z)
    } else {
        1.0 - z
    }
}

/// Bins over directions: `theta` bins uniform in cos α ∈ [cos_min, 1] about
/// `axis` (equal solid angles) times `phi` bins in azimuth, and one more for
/// everything else (outside the window, or no sample at all).
#[derive(Clone, Copy, Debug)]
pub struct DirectionBins {
    pub axis: Vec3,
    pub cos_min: f64,
    pub theta: usize,
    pub phi: usize,
}

impl DirectionBins {
    pub fn sphere(theta: usize, phi: usize) -> Self {
        Self { axis: Vec3::Z, cos_min: -1.0, theta, phi }
    }

    /// A window of the directions within 1 − cos ≤ `span` of `axis`.
    pub fn cone(axis: Vec3, span: f64, theta: usize, phi: usize) -> Self {
        Self { axis, cos_min: 1.0 - span, theta, phi }
    }

    fn frame(&self) -> gi_studio::geometry::Frame {
        gi_studio::geometry::Frame::from_z(self.axis)
    }

    fn span(&self) -> f64 {
        1.0 - self.cos_min
    }

    pub fn count(&self) -> usize {
        self.theta * self.phi + 1
    }

    /// The bin of direction `d` (the last one: outside the window).
    pub fn bin(&self, d: Vec3) -> usize {
        let local = self.frame().to_local(d.normalize());
        let offset = one_minus_cos(local);
        if offset > self.span() {
            return self.theta * self.phi;
        }
        let t = (((1.0 - offset / self.span()) * self.theta as f64) as usize).min(self.theta - 1);
        let phi = (local.y as f64).atan2(local.x as f64).rem_euclid(TAU);
        let p = ((phi / TAU * self.phi as f64) as usize).min(self.phi - 1);
        t * self.phi + p
    }

    /// Each bin's probability under the solid-angle density `pdf`: the
    /// midpoint rule on `sub` × `sub` cells a bin and on twice as many,
    /// extrapolated (Richardson: its h² error cancels), each cell where the
    /// pdf starts or stops (its corners and centre disagree on zero) again
    /// on 32 × 32 points. The last bin gets the rest, so the integral must
    /// be good to a few samples in 200 000: a sharp lobe's or a light's
    /// edge would otherwise put a few hundred samples' worth of error there,
    /// where the sampler puts none.
    pub fn probabilities(&self, sub: usize, pdf: impl Fn(Vec3) -> f64) -> Vec<f64> {
        let coarse = self.midpoint(sub, &pdf);
        let fine = self.midpoint(2 * sub, &pdf);
        let mut p: Vec<f64> = coarse.iter().zip(&fine).map(|(c, f)| (4.0 * f - c) / 3.0).collect();
        let inside: f64 = p[..self.theta * self.phi].iter().sum();
        p[self.theta * self.phi] = (1.0 - inside).max(0.0);
        p
    }

    fn midpoint(&self, sub: usize, pdf: &impl Fn(Vec3) -> f64) -> Vec<f64> {
        const REFINE: usize = 32;
        let frame = self.frame();
        let span = self.span();
        let (rows, columns) = (self.theta * sub, self.phi * sub);
        // Cell (i, j): 1 − cos from span·(1 − i/rows) down, φ from 2πj/columns
        let direction = |i: f64, j: f64| {
            let offset = span * (1.0 - i / rows as f64);
            let sin = (offset * (2.0 - offset)).max(0.0).sqrt();
            let phi = j / columns as f64 * TAU;
            frame.to_world(Vec3::new((sin * phi.cos()) as f32, (sin * phi.sin()) as f32, (1.0 - offset) as f32))
        };
        let cell = span / rows as f64 * TAU / columns as f64;
        let corners: Vec<bool> = (0..=rows)
            .flat_map(|i| (0..=columns).map(move |j| (i, j)))
            .map(|(i, j)| pdf(direction(i as f64, j as f64)) > 0.0)
            .collect();
        let mut p = vec![0.0; self.count()];
        for i in 0..rows {
            for j in 0..columns {
                let centre = pdf(direction(i as f64 + 0.5, j as f64 + 0.5));
                let at = |di: usize, dj: usize| corners[(i + di) * (columns + 1) + j + dj];
                let edge = [at(0, 0), at(0, 1), at(1, 0), at(1, 1)].iter().any(|c| *c != (centre > 0.0));
                let integral = if edge {
                    let mut sum = 0.0;
                    for a in 0..REFINE {
                        for b in 0..REFINE {
                            let (u, v) = ((a as f64 + 0.5) / REFINE as f64, (b as f64 + 0.5) / REFINE as f64);
                            sum += pdf(direction(i as f64 + u, j as f64 + v));
                        }
                    }
                    sum / (REFINE * REFINE) as f64
                } else {
                    centre
                };
                p[(i / sub) * self.phi + j / sub] += integral * cell;
            }
        }
        p
    }

    /// χ² of `samples` draws (None: no direction) against `pdf`.
    pub fn test(
        &self,
        samples: usize,
        mut draw: impl FnMut() -> Option<Vec3>,
        sub: usize,
        pdf: impl Fn(Vec3) -> f64,
    ) -> ChiSquare {
        let mut observed = vec![0.0; self.count()];
        for _ in 0..samples {
            let bin = draw().map_or(self.count() - 1, |d| self.bin(d));
            observed[bin] += 1.0;
        }
        let expected: Vec<f64> = self.probabilities(sub, pdf).iter().map(|p| p * samples as f64).collect();
        chi_square(&observed, &expected)
    }
}

impl DirectionBins {
    /// Weighted draws (a photon's direction and power) against the
    /// density of weight per solid angle `density`: each bin's mean weight
    /// per draw against the density's integral over it, as z-scores with
    /// the bin's own sample variance, summed: χ² with as many degrees of
    /// freedom as bins that get weight (bins of one weight sample are
    /// normal by the central limit theorem at these counts). A scale error
    /// spreads thin over the bins: the total, the mean weight per draw
    /// against the density's integral, is returned too, as a z-score.
    pub fn weighted_test(
        &self,
        samples: usize,
        mut draw: impl FnMut() -> Option<(Vec3, f64)>,
        sub: usize,
        density: impl Fn(Vec3) -> f64,
    ) -> (ChiSquare, f64) {
        let (mut sums, mut squares) = (vec![0.0; self.count()], vec![0.0; self.count()]);
        let (mut total, mut total_squares) = (0.0, 0.0);
        for _ in 0..samples {
            if let Some((d, w)) = draw() {
                let bin = self.bin(d);
                sums[bin] += w;
                squares[bin] += w * w;
                total += w;
                total_squares += w * w;
            }
        }
        let expected = self.midpoint(2 * sub, &density);
        let n = samples as f64;
        let (mut statistic, mut dof) = (0.0, 0);
        for b in 0..self.theta * self.phi {
            let mean = sums[b] / n;
            let variance = (squares[b] / n - mean * mean).max(0.0) / (n - 1.0);
            if variance > 0.0 {
                statistic += (mean - expected[b]).powi(2) / variance;
                dof += 1;
            } else if expected[b] > 1e-9 {
                statistic = f64::INFINITY;
            }
        }
        let dof = dof.max(1);
        let (mean, want) = (total / n, expected.iter().sum::<f64>());
        // A weight the same for every draw has no spread: then only rounding
        let spread = ((total_squares / n - mean * mean).max(0.0) / (n - 1.0)).sqrt().max(1e-5 * want);
        (ChiSquare { statistic, dof, p_value: chi_square_p_value(statistic, dof) }, (mean - want) / spread)
    }
}
