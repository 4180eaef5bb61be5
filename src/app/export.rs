//! Saving what the user sees: a pane's image (PNG tone-mapped, EXR linear)
//! and the difference between two images in false colour.

use std::path::Path;

use crate::analysis::metrics::{false_colour, per_pixel_rel_error};
use crate::render::image::ImageError;
use crate::render::LinearImage;

pub fn export_image(image: &LinearImage, exposure: f32, path: &Path) -> Result<(), ImageError> {
    image.save(path, exposure)
}

/// |A − B| as relative error per pixel, in false colour (RGBA8), with the
/// colour scale's top value; None if the sizes differ.
pub fn difference_rgba(a: &LinearImage, b: &LinearImage) -> Option<(Vec<u8>, f64)> {
    let errors = per_pixel_rel_error(a, b, 1e-2).ok()?;
    // Scale to the 99th percentile so a few outliers do not wash it out
    let mut sorted: Vec<f64> = errors.iter().copied().filter(|e| e.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let top = sorted.get(sorted.len() * 99 / 100).copied().unwrap_or(1.0).max(1e-6);
    Some((false_colour(&errors, top).into_iter().flatten().collect(), top))
}
