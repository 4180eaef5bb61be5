//! Linear-light images and their display: exposure, sRGB, PNG and EXR.

use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first, linear RGB radiance.
    pub pixels: Vec<[f32; 3]>,
}

#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("{path}: unsupported image extension (use .png or .exr)")]
    UnknownFormat { path: String },
    #[error("{path}: {source}")]
    Write { path: String, source: image::ImageError },
    #[error("{path}: {source}")]
    Read { path: String, source: image::ImageError },
}

/// sRGB opto-electronic transfer function on [0, 1].
#[inline]
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Display value of one linear pixel: 2^exposure scale, clamp, sRGB, 8 bits.
/// Non-finite input (which the engine never produces) shows as black.
#[inline]
pub fn tonemap_srgb8(linear: [f32; 3], exposure_stops: f32) -> [u8; 3] {
    let scale = exposure_stops.exp2();
    linear.map(|c| {
        let v = c * scale;
        if !v.is_finite() {
            return 0;
        }
        (srgb_encode(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
    })
}

impl LinearImage {
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![[0.0; 3]; width as usize * height as usize] }
    }

    #[inline]
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    pub fn to_rgba8(&self, exposure_stops: f32) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| {
                let [r, g, b] = tonemap_srgb8(*p, exposure_stops);
                [r, g, b, 255]
            })
            .collect()
    }

    pub fn mean(&self) -> [f64; 3] {
        let n = self.pixels.len().max(1) as f64;
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        sum.map(|s| s / n)
    }

    /// Box-filter down by an integer factor: each output pixel averages a
    /// factor × factor block, which is exactly what a render at the smaller
    /// size estimates (pixels integrate over their area).
    pub fn downsample(&self, factor: u32) -> LinearImage {
        let factor = factor.max(1);
        let (width, height) = (self.width / factor, self.height / factor);
        let mut out = LinearImage::new(width, height);
        let weight = 1.0 / (factor * factor) as f64;
        for y in 0..height {
            for x in 0..width {
                let mut sum = [0.0f64; 3];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let p = self.get(x * factor + dx, y * factor + dy);
                        (0..3).for_each(|c| sum[c] += p[c] as f64);
                    }
                }
                out.pixels[(y * width + x) as usize] = sum.map(|s| (s * weight) as f32);
            }
        }
        out
    }

    /// This image at `width × height` if that divides it evenly (itself when
    /// the size already matches).
    pub fn at_size(&self, width: u32, height: u32) -> Option<std::borrow::Cow<'_, LinearImage>> {
        if (self.width, self.height) == (width, height) {
            return Some(std::borrow::Cow::Borrowed(self));
        }
        let factor = self.width / width.max(1);
        (factor > 1 && width * factor == self.width && height * factor == self.height)
            .then(|| std::borrow::Cow::Owned(self.downsample(factor)))
    }

    /// `.png`: tone-mapped sRGB 8-bit; `.exr`: linear 32-bit float.
    pub fn save(&self, path: &Path, exposure_stops: f32) -> Result<(), ImageError> {
        let name = path.display().to_string();
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let result = match extension.as_deref() {
            Some("png") => {
                let rgb: Vec<u8> = self.pixels.iter().flat_map(|p| tonemap_srgb8(*p, exposure_stops)).collect();
                image::save_buffer(path, &rgb, self.width, self.height, image::ExtendedColorType::Rgb8)
            }
            Some("exr") => {
                let data: Vec<f32> = self.pixels.iter().flatten().copied().collect();
                match image::Rgb32FImage::from_raw(self.width, self.height, data) {
                    Some(buffer) => buffer.save(path),
                    None => dimension_mismatch(),
                }
            }
            _ => return Err(ImageError::UnknownFormat { path: name }),
        };
        result.map_err(|source| ImageError::Write { path: name, source })
    }

    /// Load a linear EXR (references) or an 8-bit image decoded from sRGB.
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let name = path.display().to_string();
        let decoded = image::open(path).map_err(|source| ImageError::Read { path: name, source })?;
        let is_exr = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let rgb = decoded.to_rgb32f();
        let (width, height) = rgb.dimensions();
        let pixels = rgb.pixels().map(|p| if is_exr { p.0 } else { p.0.map(srgb_decode) }).collect();
        Ok(Self { width, height, pixels })
    }
}

fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The fields are public: an image whose pixel count disagrees with its size
/// is refused as the PNG path refuses it.
fn dimension_mismatch() -> image::ImageResult<()> {
    Err(image::ImageError::Parameter(image::error::ParameterError::from_kind(
        image::error::ParameterErrorKind::DimensionMismatch,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tonemap_known_points() {
        assert_eq!(tonemap_srgb8([0.0, 1.0, 0.5], 0.0), [0, 255, 188]);
        assert_eq!(tonemap_srgb8([0.25, 2.0, f32::NAN], 1.0), [188, 255, 0]);
        assert_eq!(tonemap_srgb8([-1.0, f32::INFINITY, 0.0], 0.0), [0, 0, 0]);
    }

    #[test]
    fn downsampling_averages_blocks() {
        let mut img = LinearImage::new(4, 2);
        img.pixels[0] = [4.0, 0.0, 0.0];
        img.pixels[5] = [0.0, 8.0, 0.0];
        let small = img.at_size(2, 1).unwrap();
        assert_eq!(small.pixels, vec![[1.0, 2.0, 0.0], [0.0; 3]]);
        assert!(img.at_size(3, 1).is_none());
        assert!(matches!(img.at_size(4, 2), Some(std::borrow::Cow::Borrowed(_))));
    }

    #[test]
    fn exr_round_trip_is_exact_and_png_decodes_to_size() {
        let dir = std::env::temp_dir().join(format!("gi-image-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut img = LinearImage::new(3, 2);
        img.pixels[4] = [1.5, 0.25, 1e-3];
        img.save(&dir.join("a.exr"), 0.0).unwrap();
        assert_eq!(LinearImage::load(&dir.join("a.exr")).unwrap(), img);
        img.save(&dir.join("a.png"), 0.0).unwrap();
        let png = LinearImage::load(&dir.join("a.png")).unwrap();
        assert_eq!((png.width, png.height), (3, 2));
        assert!(matches!(img.save(&dir.join("a.bmpx"), 0.0), Err(ImageError::UnknownFormat { .. })));
    }
}
