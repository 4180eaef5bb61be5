//! Error metrics between a rendered image and a reference: RMSE, relMSE
//! (with optional outlier rejection), SSIM on tone-mapped luminance, and
//! per-pixel relative error in false colour.

use super::reference::Reference;
use crate::render::film::{TermSums, REL_MSE_EPSILON};
use crate::render::image::{srgb_encode, LinearImage, Tonemap};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricError {
    #[error("image sizes differ: {test_width}×{test_height} against a {reference_width}×{reference_height} reference")]
    SizeMismatch { test_width: u32, test_height: u32, reference_width: u32, reference_height: u32 },
    #[error("the images are empty")]
    Empty,
}

fn check(test: &LinearImage, reference: &LinearImage) -> Result<(), MetricError> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(MetricError::SizeMismatch {
            test_width: test.width,
            test_height: test.height,
            reference_width: reference.width,
            reference_height: reference.height,
        });
    }
    if test.pixels.is_empty() {
        return Err(MetricError::Empty);
    }
    Ok(())
}

/// Root-mean-square error over all pixels and channels.
pub fn rmse(test: &LinearImage, reference: &LinearImage) -> Result<f64, MetricError> {
    check(test, reference)?;
    let sum: f64 = test
        .pixels
        .iter()
        .zip(&reference.pixels)
        .flat_map(|(t, r)| (0..3).map(move |c| (t[c] as f64 - r[c] as f64).powi(2)))
        .sum();
    Ok((sum / (3 * test.pixels.len()) as f64).sqrt())
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RelMseOptions {
    /// Keeps dark reference pixels from dominating: (x − r)²/(r² + ε).
    pub epsilon: f64,
    /// Drop this fraction of the largest per-pixel errors (e.g. 1e-4: the top
    /// 0.01%), so a few fireflies do not hide the trend.
    pub reject_top_fraction: f64,
}

impl Default for RelMseOptions {
    fn default() -> Self {
        Self { epsilon: REL_MSE_EPSILON, reject_top_fraction: 0.0 }
    }
}

/// relMSE against a reference, with what the reference's own noise makes
/// of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorEstimate {
    /// The test image's relMSE against the image the reference converges
    /// to: the raw relMSE less the reference's noise (`noise_floor`).
    pub rel_mse: f64,
    /// Its standard error over the pixels.
    pub standard_error: f64,
    /// What the reference's noise adds to the raw relMSE (the raw curve
    /// flattens there; that is the reference, not bias). None where the
    /// reference carries no variance, and then nothing is subtracted.
    pub noise_floor: Option<f64>,
}

/// relMSE of `test` against `reference`, corrected for the reference's
/// noise: for independent estimates E[(t − r)²] = E[(t − μ)²] + Var(r), so
/// each pixel's Var(r)/(r̃² + ε) is taken off its term, where r̃ is the
/// reference smoothed within its own noise (`relative_to`).
pub fn rel_mse_against(test: &LinearImage, reference: &Reference) -> Result<ErrorEstimate, MetricError> {
    let image = &reference.image;
    check(test, image)?;
    let variance = reference.variance.as_ref().filter(|v| (v.width, v.height) == (image.width, image.height));
    let relative_to = relative_to(image, variance);
    let (mut terms, mut floor) = (TermSums::default(), TermSums::default());
    for (i, (t, r)) in test.pixels.iter().zip(&image.pixels).enumerate() {
        for c in 0..3 {
            let (t, r, smooth) = (t[c] as f64, r[c] as f64, relative_to[i][c]);
            let scale = 1.0 / (smooth * smooth + REL_MSE_EPSILON);
            let noise = variance.map_or(0.0, |v| v.pixels[i][c] as f64 * scale);
            terms.push((t - r).powi(2) * scale - noise);
            floor.push(noise);
        }
    }
    let estimate = terms.estimate().ok_or(MetricError::Empty)?;
    Ok(ErrorEstimate {
        rel_mse: estimate.rel_mse,
        standard_error: estimate.standard_error,
        noise_floor: variance.and(floor.estimate()).map(|f| f.rel_mse),
    })
}

/// What each pixel's error is relative to: the reference, smoothed over
/// its 3×3 neighbours that lie within its noise. A reference still being
/// made is noisy, and 1/r² of a noisy r is biased: low draws inflate their
/// terms, a firefly silences its own (`tests/references.rs`). A neighbour
/// counts by how many standard deviations of a difference it lies from the
/// pixel, so a converged reference (no variance) and an edge keep their own
/// value, and a noisy flat region its mean; a plain mean would lower every
/// term along an edge, a median erase thin features.
fn relative_to(image: &LinearImage, variance: Option<&LinearImage>) -> Vec<[f64; 3]> {
    let own = || image.pixels.iter().map(|p| p.map(f64::from)).collect();
    let Some(variance) = variance else { return own() };
    let (width, height) = (image.width as usize, image.height as usize);
    let mut smoothed = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let mut pixel = [0.0; 3];
            for (c, value) in pixel.iter_mut().enumerate() {
                let (r, v) = (image.pixels[i][c] as f64, variance.pixels[i][c] as f64);
                let (mut sum, mut weights) = (0.0, 0.0);
                for ny in y.saturating_sub(1)..(y + 2).min(height) {
                    for nx in x.saturating_sub(1)..(x + 2).min(width) {
                        let j = ny * width + nx;
                        let (rj, vj) = (image.pixels[j][c] as f64, variance.pixels[j][c] as f64);
                        // Apart by q = d² / (8 σ²) of their difference: 1 at
                        // q = 0, ½ at 2.8 σ, under 0.06 beyond 5.7 σ
                        let spread = 8.0 * (v + vj);
                        let q = if spread > 0.0 { (r - rj).powi(2) / spread } else { f64::INFINITY };
                        let weight = if j == i { 1.0 } else { 1.0 / (1.0 + q * q) };
                        sum += weight * rj;
                        weights += weight;
                    }
                }
                *value = sum / weights;
            }
            smoothed.push(pixel);
        }
    }
    smoothed
}

/// Per-pixel relative squared error, averaged over channels.
pub fn per_pixel_rel_error(test: &LinearImage, reference: &LinearImage, epsilon: f64) -> Result<Vec<f64>, MetricError> {
    check(test, reference)?;
    Ok(test
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(t, r)| {
            (0..3).map(|c| (t[c] as f64 - r[c] as f64).powi(2) / ((r[c] as f64).powi(2) + epsilon)).sum::<f64>() / 3.0
        })
        .collect())
}

/// Mean relative squared error, the standard measure for Monte Carlo
/// convergence (it halves when the sample count doubles).
pub fn rel_mse(test: &LinearImage, reference: &LinearImage, options: RelMseOptions) -> Result<f64, MetricError> {
    let mut errors = per_pixel_rel_error(test, reference, options.epsilon)?;
    let reject = ((errors.len() as f64) * options.reject_top_fraction).floor() as usize;
    let keep = errors.len() - reject.min(errors.len() - 1);
    if keep < errors.len() {
        // Partition so the `keep` smallest come first; no full sort
        errors.select_nth_unstable_by(keep - 1, f64::total_cmp);
        errors.truncate(keep);
    }
    Ok(errors.iter().sum::<f64>() / errors.len() as f64)
}

/// Display luminance in [0, 1]: exposure, clamp, sRGB, Rec. 709 weights.
fn display_luminance(image: &LinearImage, exposure: f32) -> Vec<f64> {
    let scale = exposure.exp2();
    image
        .pixels
        .iter()
        .map(|p| {
            let encoded = p.map(|c| {
                let v = c * scale;
                if v.is_finite() {
                    srgb_encode(v.clamp(0.0, 1.0)) as f64
                } else {
                    0.0
                }
            });
            0.2126 * encoded[0] + 0.7152 * encoded[1] + 0.0722 * encoded[2]
        })
        .collect()
}

/// Mean SSIM (Wang et al. 2004) of the tone-mapped luminance, Gaussian
/// window 11×11 with σ = 1.5, clipped at the borders (weights renormalised).
pub fn ssim(test: &LinearImage, reference: &LinearImage, exposure: f32) -> Result<f64, MetricError> {
    check(test, reference)?;
    const C1: f64 = 0.01 * 0.01;
    const C2: f64 = 0.03 * 0.03;
    let (w, h) = (test.width as i64, test.height as i64);
    let (x, y) = (display_luminance(test, exposure), display_luminance(reference, exposure));
    let kernel: Vec<f64> = (-5..=5).map(|i: i64| (-(i * i) as f64 / (2.0 * 1.5 * 1.5)).exp()).collect();
    let mut total = 0.0;
    for py in 0..h {
        for px in 0..w {
            let (mut sw, mut mx, mut my, mut xx, mut yy, mut xy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for dy in -5..=5i64 {
                let qy = py + dy;
                if qy < 0 || qy >= h {
                    continue;
                }
                for dx in -5..=5i64 {
                    let qx = px + dx;
                    if qx < 0 || qx >= w {
                        continue;
                    }
                    let k = kernel[(dy + 5) as usize] * kernel[(dx + 5) as usize];
                    let i = (qy * w + qx) as usize;
                    sw += k;
                    mx += k * x[i];
                    my += k * y[i];
                    xx += k * x[i] * x[i];
                    yy += k * y[i] * y[i];
                    xy += k * x[i] * y[i];
                }
            }
            let (mx, my) = (mx / sw, my / sw);
            let vx = (xx / sw - mx * mx).max(0.0);
            let vy = (yy / sw - my * my).max(0.0);
            let cov = xy / sw - mx * my;
            total += ((2.0 * mx * my + C1) * (2.0 * cov + C2)) / ((mx * mx + my * my + C1) * (vx + vy + C2));
        }
    }
    Ok(total / (w * h) as f64)
}

/// Mean FLIP (Andersson et al. 2020, NVIDIA's reference implementation) of
/// the tone-mapped sRGB images: the perceived difference, 0 for identical.
pub fn flip(test: &LinearImage, reference: &LinearImage, exposure: f32) -> Result<f64, MetricError> {
    check(test, reference)?;
    let tonemap = Tonemap::new(exposure);
    let srgb = |image: &LinearImage| -> Vec<u8> { image.pixels.iter().flat_map(|p| tonemap.pixel(*p)).collect() };
    let (width, height) = (test.width, test.height);
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &srgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &srgb(test));
    let map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    Ok(nv_flip::FlipPool::from_image(&map).mean() as f64)
}

/// Magma-like control points, dark (no error) to bright (large error).
const MAGMA: [[u8; 3]; 9] = [
    [0, 0, 4],
    [28, 16, 68],
    [79, 18, 123],
    [129, 37, 129],
    [181, 54, 122],
    [229, 80, 100],
    [251, 135, 97],
    [254, 194, 135],
    [252, 253, 191],
];
/// Non-finite values stand out in a colour the map never uses.
pub const FLAG_COLOUR: [u8; 4] = [0, 255, 0, 255];

/// Map values in [0, max] to RGBA along a perceptual colour map.
pub fn false_colour(values: &[f64], max: f64) -> Vec<[u8; 4]> {
    values
        .iter()
        .map(|v| {
            if !v.is_finite() {
                return FLAG_COLOUR;
            }
            let t = if max > 0.0 { (v / max).clamp(0.0, 1.0) } else { 0.0 } * (MAGMA.len() - 1) as f64;
            let i = (t.floor() as usize).min(MAGMA.len() - 2);
            let f = t - i as f64;
            let (a, b) = (MAGMA[i], MAGMA[i + 1]);
            let mix = |c: usize| (a[c] as f64 + (b[c] as f64 - a[c] as f64) * f).round() as u8;
            [mix(0), mix(1), mix(2), 255]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> LinearImage {
        LinearImage {
            width: w,
            height: h,
            pixels: (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect(),
        }
    }

    fn gradient() -> LinearImage {
        image(32, 24, |x, y| [x as f32 / 32.0, y as f32 / 24.0, 0.5])
    }

    fn noisy(base: &LinearImage, amplitude: f32, seed: u64) -> LinearImage {
        let mut s = Sampler::new(0, 0, seed);
        let mut out = base.clone();
        for p in &mut out.pixels {
            for c in p.iter_mut() {
                *c = (*c + (s.next_f32() - 0.5) * amplitude).max(0.0);
            }
        }
        out
    }

    /// relMSE against a stored reference is the definition written out in
    /// f64, pixel by pixel and channel by channel: ((t − r)² − Var r) /
    /// (r̃² + ε), averaged, r̃ the reference smoothed within its noise;
    /// without a variance r̃ = r and it is `rel_mse`'s figure.
    #[test]
    fn rel_mse_against_a_reference_is_its_definition() {
        use crate::analysis::reference::ReferenceInfo;
        let r = gradient();
        let t = noisy(&r, 0.3, 3);
        let variance = noisy(&image(32, 24, |_, _| [0.0; 3]), 0.02, 4);
        let info = ReferenceInfo {
            scene: "gradient".into(),
            key: String::new(),
            algorithm: "path".into(),
            width: 32,
            height: 24,
            samples_per_pixel: 1,
            seconds: 0.0,
            seed: 0,
            program_version: String::new(),
        };
        let plain = Reference { image: r.clone(), variance: None, info: info.clone() };
        let with_noise = Reference { image: r.clone(), variance: Some(variance.clone()), info };
        let definition = |variance: Option<&LinearImage>| {
            let smooth = relative_to(&r, variance);
            let mut sum = 0.0;
            for (i, (tp, rp)) in t.pixels.iter().zip(&r.pixels).enumerate() {
                for c in 0..3 {
                    let (tv, rv, sv) = (tp[c] as f64, rp[c] as f64, smooth[i][c]);
                    let var = variance.map_or(0.0, |v| v.pixels[i][c] as f64);
                    sum += ((tv - rv) * (tv - rv) - var) / (sv * sv + REL_MSE_EPSILON);
                }
            }
            sum / (3 * t.pixels.len()) as f64
        };
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        let got = rel_mse_against(&t, &plain).unwrap().rel_mse;
        assert!(close(got, definition(None)), "{got} against {}", definition(None));
        assert!(close(got, rel_mse(&t, &r, RelMseOptions::default()).unwrap()));
        let got = rel_mse_against(&t, &with_noise).unwrap().rel_mse;
        assert!(close(got, definition(Some(&variance))), "{got} against {}", definition(Some(&variance)));
        assert!(definition(Some(&variance)) < definition(None));
    }

    /// The reference errors are relative to: itself without a variance; a
    /// flat noisy region's 3×3 mean; across an edge far beyond the noise,
    /// each side its own value.
    #[test]
    fn errors_are_relative_to_the_reference_smoothed_within_its_noise() {
        let flat = noisy(&image(8, 8, |_, _| [0.5; 3]), 0.02, 7);
        assert_eq!(relative_to(&flat, None), flat.pixels.iter().map(|p| p.map(f64::from)).collect::<Vec<_>>());
        // Noise of σ = 0.1 in each pixel: the flat region's values all lie within it
        let variance = image(8, 8, |_, _| [0.01; 3]);
        let smooth = relative_to(&flat, Some(&variance));
        let (x, y) = (3, 4);
        let mean: f64 = (0..9).map(|k| flat.pixels[(y + k / 3 - 1) * 8 + x + k % 3 - 1][1] as f64).sum::<f64>() / 9.0;
        let own = flat.pixels[y * 8 + x][1] as f64;
        let smoothed = smooth[y * 8 + x][1];
        assert!((smoothed - mean).abs() < 0.02 * (own - mean).abs().max(1e-3), "{smoothed} against mean {mean}");
        // 0 beside 10 with σ = 0.1: a hundred standard deviations apart
        let edge = image(8, 8, |x, _| if x < 4 { [0.0; 3] } else { [10.0; 3] });
        let smooth = relative_to(&edge, Some(&variance));
        for (s, e) in smooth.iter().zip(&edge.pixels) {
            assert!((s[0] - e[0] as f64).abs() < 1e-3 * (1.0 + e[0] as f64), "{} became {}", e[0], s[0]);
        }
    }

    #[test]
    fn rmse_of_identical_is_zero_and_of_an_offset_is_the_offset() {
        let a = gradient();
        assert_eq!(rmse(&a, &a).unwrap(), 0.0);
        let mut b = a.clone();
        b.pixels.iter_mut().for_each(|p| p.iter_mut().for_each(|c| *c += 0.25));
        assert!((rmse(&b, &a).unwrap() - 0.25).abs() < 1e-6);
    }

    #[test]
    fn rel_mse_by_hand_and_rejection_removes_the_outlier() {
        let reference = image(2, 1, |_, _| [1.0; 3]);
        let test = image(2, 1, |x, _| if x == 0 { [2.0; 3] } else { [1.0; 3] });
        // Pixel 0: (2−1)²/(1 + 0.01) per channel; pixel 1: 0
        let expected = (1.0 / 1.01) / 2.0;
        assert!((rel_mse(&test, &reference, RelMseOptions::default()).unwrap() - expected).abs() < 1e-12);

        let reference = image(100, 100, |_, _| [0.5; 3]);
        let clean = image(100, 100, |x, _| [0.5 + 0.01 * (x % 2) as f32; 3]);
        let mut spiked = clean.clone();
        spiked.pixels[1234] = [1e6; 3];
        let options = RelMseOptions { reject_top_fraction: 1e-4, ..Default::default() };
        let clean_error = rel_mse(&clean, &reference, RelMseOptions::default()).unwrap();
        let spiked_error = rel_mse(&spiked, &reference, options).unwrap();
        // Rejection drops the spike; the mean is then over one pixel fewer
        assert!(
            (spiked_error - clean_error * 10_000.0 / 9_999.0).abs() < 1e-9 * clean_error.max(1.0) + 1e-6 * clean_error
        );
        assert!(rel_mse(&spiked, &reference, RelMseOptions::default()).unwrap() > 1e3);
    }

    /// Rejection never empties the mean: asking to drop every pixel keeps
    /// the one with the smallest error.
    #[test]
    fn rejecting_everything_keeps_the_best_pixel() {
        let reference = image(3, 1, |_, _| [1.0; 3]);
        let test = image(3, 1, |x, _| [[3.0; 3], [1.5; 3], [2.0; 3]][x as usize]);
        let all = RelMseOptions { reject_top_fraction: 1.0, ..Default::default() };
        let best = 0.25 / (1.0 + RelMseOptions::default().epsilon);
        assert!((rel_mse(&test, &reference, all).unwrap() - best).abs() < 1e-12);
    }

    #[test]
    fn sizes_must_match() {
        let a = gradient();
        let b = image(3, 3, |_, _| [0.0; 3]);
        assert!(matches!(rmse(&a, &b), Err(MetricError::SizeMismatch { .. })));
        assert!(matches!(ssim(&a, &b, 0.0), Err(MetricError::SizeMismatch { .. })));
    }

    #[test]
    fn ssim_is_one_for_identical_symmetric_and_falls_with_noise() {
        let a = gradient();
        assert!((ssim(&a, &a, 0.0).unwrap() - 1.0).abs() < 1e-12);
        let b = noisy(&a, 0.1, 1);
        assert!((ssim(&a, &b, 0.0).unwrap() - ssim(&b, &a, 0.0).unwrap()).abs() < 1e-12);
        let mut last = 1.0;
        for amplitude in [0.02, 0.1, 0.3, 0.8] {
            let s = ssim(&noisy(&a, amplitude, 2), &a, 0.0).unwrap();
            assert!(s < last, "amplitude {amplitude}: {s} ≥ {last}");
            last = s;
        }
    }

    /// SSIM against an oracle written out from Wang et al.'s definition in
    /// f64, another way: the 2-D Gaussian taken whole, variances and the
    /// covariance as weighted second moments about the mean (not E[x²] −
    /// m²), sRGB from its formula in f64, Rec. 709 luminance. Colour images
    /// under an exposure that clips some pixels; windows cut by every border
    /// (9 × 7 is smaller than the 11 × 11 window).
    #[test]
    fn ssim_agrees_with_the_definition_written_out() {
        fn luminance(p: [f32; 3], exposure: f64) -> f64 {
            let encode = |c: f32| {
                let v = (c as f64 * exposure.exp2()).clamp(0.0, 1.0);
                if v <= 0.0031308 {
                    12.92 * v
                } else {
                    1.055 * v.powf(1.0 / 2.4) - 0.055
                }
            };
            0.2126 * encode(p[0]) + 0.7152 * encode(p[1]) + 0.0722 * encode(p[2])
        }
        fn oracle(a: &LinearImage, b: &LinearImage, exposure: f64) -> f64 {
            let (w, h) = (a.width as i64, a.height as i64);
            let (c1, c2) = (0.0001, 0.0009);
            let mut total = 0.0;
            for (py, px) in (0..h).flat_map(|y| (0..w).map(move |x| (y, x))) {
                let window: Vec<(f64, f64, f64)> = (0..h)
                    .flat_map(|y| (0..w).map(move |x| (y, x)))
                    .filter(|(y, x)| (y - py).abs() <= 5 && (x - px).abs() <= 5)
                    .map(|(y, x)| {
                        let d2 = ((y - py).pow(2) + (x - px).pow(2)) as f64;
                        let i = (y * w + x) as usize;
                        ((-d2 / 4.5).exp(), luminance(a.pixels[i], exposure), luminance(b.pixels[i], exposure))
                    })
                    .collect();
                let weight: f64 = window.iter().map(|t| t.0).sum();
                let mean =
                    |f: &dyn Fn(&(f64, f64, f64)) -> f64| window.iter().map(|t| t.0 * f(t)).sum::<f64>() / weight;
                let (mx, my) = (mean(&|t| t.1), mean(&|t| t.2));
                let vx = mean(&|t| (t.1 - mx).powi(2));
                let vy = mean(&|t| (t.2 - my).powi(2));
                let cov = mean(&|t| (t.1 - mx) * (t.2 - my));
                total += (2.0 * mx * my + c1) * (2.0 * cov + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            }
            total / (w * h) as f64
        }
        let colour = |seed: u64| {
            let s = std::cell::RefCell::new(Sampler::new(0, 0, seed));
            image(9, 7, move |_, _| {
                let mut s = s.borrow_mut();
                [s.next_f32() * 1.5, s.next_f32(), s.next_f32() * 0.3]
            })
        };
        let (a, b) = (colour(11), colour(12));
        let c = noisy(&a, 0.2, 4);
        for (exposure, x, y) in [(0.0, &a, &b), (0.0, &a, &c), (1.0, &c, &a), (-2.0, &b, &c)] {
            let expected = oracle(x, y, exposure as f64);
            let got = ssim(x, y, exposure).unwrap();
            assert!((got - expected).abs() < 1e-6, "exposure {exposure}: {got} against {expected}");
        }
    }

    #[test]
    fn flip_is_zero_for_identical_and_grows_with_noise() {
        let a = gradient();
        assert_eq!(flip(&a, &a, 0.0).unwrap(), 0.0);
        let small = flip(&noisy(&a, 0.05, 3), &a, 0.0).unwrap();
        let large = flip(&noisy(&a, 0.5, 3), &a, 0.0).unwrap();
        assert!(small > 0.0 && large > small, "{small} {large}");
    }

    #[test]
    fn false_colour_ends_and_flag() {
        let colours = false_colour(&[0.0, 1.0, 2.0, f64::NAN], 1.0);
        assert_eq!(colours[0], [0, 0, 4, 255]);
        assert_eq!(colours[1], [252, 253, 191, 255]);
        assert_eq!(colours[2], colours[1]);
        assert_eq!(colours[3], FLAG_COLOUR);
        // An error map with no error (max 0) is all the bottom colour
        assert_eq!(false_colour(&[0.0, 0.5], 0.0), vec![[0, 0, 4, 255]; 2]);
        // Values are read as fractions of `max`: half of it is the middle
        // control point, and a sixteenth half way between the first two
        let scaled = false_colour(&[0.0, 2.0, 0.25, 4.0, 8.0], 4.0);
        assert_eq!(scaled[..2], [[0, 0, 4, 255], [181, 54, 122, 255]]);
        assert_eq!(scaled[2], [14, 8, 36, 255]);
        assert_eq!(scaled[3..], [[252, 253, 191, 255]; 2]);
    }
}
