//! A photon's incoming direction in two bytes, as Jensen packs it: θ and φ
//! each in 256 steps, and the tables that turn the steps back into a
//! vector. The steps are the ones `acos` and `atan2` give (⌊acos z · 256/π⌋
//! and ⌊atan2(y, x) · 256/2π⌋ wrapped), which photon maps have always held,
//! but found without either: those two calls were a tenth of an SPPM pass
//! on cornell. θ is read from the steps' bounds in z; φ from a polynomial,
//! asking `atan2` only where the polynomial's error could cross a step.

use std::f32::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

/// cos θ, sin θ, cos φ, sin φ at the centres of the 256 steps, and the
/// bounds of the θ steps.
pub(super) struct DirectionTables {
    pub cos_theta: [f32; 256],
    pub sin_theta: [f32; 256],
    pub cos_phi: [f32; 256],
    pub sin_phi: [f32; 256],
    /// `theta_bounds[k]` (k ≥ 1): the largest z whose θ step is k or more
    /// (steps fall as z grows); `[0]` is never read.
    theta_bounds: [f32; 256],
}

pub(super) fn tables() -> &'static DirectionTables {
    static TABLES: OnceLock<DirectionTables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = DirectionTables {
            cos_theta: [0.0; 256],
            sin_theta: [0.0; 256],
            cos_phi: [0.0; 256],
            sin_phi: [0.0; 256],
            theta_bounds: [f32::INFINITY; 256],
        };
        for i in 0..256 {
            let theta = (i as f32 + 0.5) * (PI / 256.0);
            let phi = (i as f32 + 0.5) * (2.0 * PI / 256.0);
            t.cos_theta[i] = theta.cos();
            t.sin_theta[i] = theta.sin();
            t.cos_phi[i] = phi.cos();
            t.sin_phi[i] = phi.sin();
        }
        for (k, bound) in t.theta_bounds.iter_mut().enumerate().skip(1) {
            *bound = largest_z_with_theta_step(k as i32);
        }
        t
    })
}

/// The θ step by `acos`: the definition `theta_step` keeps.
fn theta_step_by_acos(z: f32) -> i32 {
    ((z.clamp(-1.0, 1.0).acos() * (256.0 / PI)) as i32).clamp(0, 255)
}

/// The largest float z in [−1, 1] with a θ step of `k` or more, by
/// bisection over the floats in order (step 255 at −1, 0 at 1, and `acos`
/// falls as z grows: the test holds `theta_step` to `acos` around every
/// bound).
fn largest_z_with_theta_step(k: i32) -> f32 {
    // Floats of one sign order as their bits; [−1, 0) and [0, 1] apart
    let rank = |z: f32| if z < 0.0 { -(((-z).to_bits()) as i64) - 1 } else { z.to_bits() as i64 };
    let float = |r: i64| if r < 0 { -f32::from_bits((-(r + 1)) as u32) } else { f32::from_bits(r as u32) };
    let (mut at_least, mut below) = (rank(-1.0), rank(1.0));
    while below - at_least > 1 {
        let middle = at_least + (below - at_least) / 2;
        if theta_step_by_acos(float(middle)) >= k {
            at_least = middle;
        } else {
            below = middle;
        }
    }
    float(at_least)
}

/// θ's step of a direction's z: how many of the bounds z is at or below,
/// by an eight-step binary search (a NaN is below none: step 0, as `acos`
/// gives it).
pub(super) fn theta_step(z: f32) -> u8 {
    let bounds = &tables().theta_bounds;
    let z = z.clamp(-1.0, 1.0);
    let mut step = 0;
    for half in [128, 64, 32, 16, 8, 4, 2, 1] {
        if z <= bounds[step + half] {
            step += half;
        }
    }
    step as u8
}

/// The φ step by `atan2`: the definition `phi_step` keeps.
fn phi_step_by_atan2(x: f32, y: f32) -> u8 {
    let mut phi = y.atan2(x) * (256.0 / (2.0 * PI));
    if phi < 0.0 {
        phi += 256.0;
    }
    (phi as i32).clamp(0, 255) as u8
}

/// How near, in steps, φ may come to a step's edge before `atan2` decides:
/// far above the polynomial's error (below 1e-5 steps, with the float
/// rounding of the quadrant's sums) and the rounding of `atan2`'s own
/// φ + 256 (3e-5 steps).
const PHI_EDGE: f32 = 1e-3;

/// φ's step of a direction (x, y): the angle by `atan` of the smaller of
/// |x|, |y| over the larger, put in its quadrant. Zeros, infinities and
/// NaNs land on an edge (or are NaN) and go to `atan2`, as does one in 500
/// directions.
pub(super) fn phi_step(x: f32, y: f32) -> u8 {
    let (ax, ay) = (x.abs(), y.abs());
    let ratio = ax.min(ay) / ax.max(ay);
    let mut angle = atan_unit(ratio);
    if ay > ax {
        angle = FRAC_PI_2 - angle;
    }
    if x < 0.0 {
        angle = PI - angle;
    }
    let mut steps = angle * (256.0 / (2.0 * PI));
    if y < 0.0 {
        steps = 256.0 - steps;
    }
    // φ's place within its step (steps ≥ 0; a NaN fails both tests)
    let within = steps - (steps as i32) as f32;
    if within > PHI_EDGE && within < 1.0 - PHI_EDGE {
        (steps as i32).clamp(0, 255) as u8
    } else {
        phi_step_by_atan2(x, y)
    }
}

/// atan t for t in [0, 1], within 2e-8 of it (Abramowitz and Stegun
/// 4.4.49) before float rounding.
fn atan_unit(t: f32) -> f32 {
    const A: [f32; 8] = [
        -0.333_331_45,
        0.199_935_51,
        -0.142_089,
        0.106_562_64,
        -0.075_289_64,
        0.042_909_614,
        -0.016_165_737,
        0.002_866_225_7,
    ];
    let t2 = t * t;
    let sum = A.iter().rev().fold(0.0, |sum, &a| sum * t2 + a);
    t + t * t2 * sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// Floats within `ulps` of `z` on either side.
    fn around(z: f32, ulps: i32) -> impl Iterator<Item = f32> {
        // Steps of the magnitude, kept to z's side of zero
        (-ulps..=ulps).map(move |u| f32::from_bits((z.abs().to_bits() as i32 + u).max(0) as u32).copysign(z))
    }

    /// Every bound, and 512 floats around it (where `acos` falls by an ulp
    /// a float, any step it took out of order would show), random z and
    /// the ends: the same step as `acos` gives.
    #[test]
    fn theta_steps_are_the_ones_acos_gives() {
        let bounds = tables().theta_bounds;
        for (k, &bound) in bounds.iter().enumerate().skip(1) {
            assert_eq!(theta_step_by_acos(bound), k as i32, "the bound is in its step");
            for z in around(bound, 256).chain(around(-bound, 256)) {
                assert_eq!(theta_step(z) as i32, theta_step_by_acos(z), "z = {z:e} (bound {k})");
            }
        }
        let mut s = Sampler::new(0, 0, 21);
        let ends = [-1.0, 1.0, 0.0, -0.0, 1.5, -7.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-30];
        for z in ends.into_iter().chain((0..200_000).map(|_| s.next_f32() * 2.0 - 1.0)) {
            assert_eq!(theta_step(z) as i32, theta_step_by_acos(z), "z = {z:e}");
        }
    }

    #[test]
    fn the_polynomial_is_atan_within_its_bound() {
        let worst = (0..=100_000)
            .map(|i| {
                let t = i as f64 / 100_000.0;
                (atan_unit(t as f32) as f64 - t.atan()).abs()
            })
            .fold(0.0, f64::max);
        // 2e-8 for the polynomial, a few ulps of π/4 for the float sums
        assert!(worst < 2e-7, "{worst:e} rad");
        assert!(worst * 256.0 / (2.0 * std::f64::consts::PI) < PHI_EDGE as f64 / 100.0);
    }

    /// Random directions; directions a hair either side of every step's
    /// edge, where only `atan2` can decide; the axes, zeros of either sign,
    /// infinities and NaNs: the same step as `atan2` gives.
    #[test]
    fn phi_steps_are_the_ones_atan2_gives() {
        let mut s = Sampler::new(1, 0, 22);
        let mut directions: Vec<(f32, f32)> = (0..300_000)
            .map(|_| {
                let d = uniform_sphere(s.next_2d());
                (d.x, d.y)
            })
            .collect();
        for edge in 0..256 {
            let phi = edge as f64 * 2.0 * std::f64::consts::PI / 256.0;
            for offset in [-1e-4, -2e-5, -3e-6, -1e-7, 0.0, 1e-7, 3e-6, 2e-5, 1e-4] {
                for r in [1.0, 1e-3, 3e4] {
                    directions.push(((r * (phi + offset).cos()) as f32, (r * (phi + offset).sin()) as f32));
                }
            }
        }
        let special = [0.0, -0.0, 1.0, -1.0, 1e-38, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        for x in special {
            for y in special {
                directions.push((x, y));
            }
        }
        let mut by_atan2 = 0;
        for (x, y) in directions {
            assert_eq!(phi_step(x, y), phi_step_by_atan2(x, y), "({x:e}, {y:e})");
            let steps = y.atan2(x).rem_euclid(2.0 * PI) * (256.0 / (2.0 * PI));
            by_atan2 += ((steps - steps.round()).abs() <= PHI_EDGE) as u32;
        }
        assert!(by_atan2 > 3000, "directions at the edges were tried ({by_atan2})");
    }
}
