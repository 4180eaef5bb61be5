//! Linear-light images and their display: exposure, sRGB, PNG and EXR.

use std::path::Path;

use crate::fileio::{self, FileError, SIGNATURE};
use crate::limits;

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
    #[error("{path}: could not encode the image: {reason}")]
    Encode { path: String, reason: String },
    #[error("{path}: {reason}")]
    Decode { path: String, reason: String },
    #[error(transparent)]
    File(#[from] FileError),
}

/// The two formats images are saved in, by their file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Tone-mapped sRGB, 8 bits.
    Png,
    /// Linear 32-bit float.
    Exr,
}

impl ImageFormat {
    pub fn of(path: &Path) -> Result<Self, ImageError> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => Err(ImageError::UnknownFormat { path: path.display().to_string() }),
        }
    }
}

/// An 8-bit PNG (RGB, or RGBA when `alpha`) carrying the program's signature
/// in a `Software` text chunk, so it is known as ours (`fileio::replaceable`).
pub fn png_bytes(width: u32, height: u32, alpha: bool, data: &[u8]) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(if alpha { png::ColorType::Rgba } else { png::ColorType::Rgb });
    encoder.set_depth(png::BitDepth::Eight);
    // fdeflate: what the image crate wrote with, many times faster than zlib's default level
    encoder.set_compression(png::Compression::Fast);
    let software = format!("{SIGNATURE} {}", env!("CARGO_PKG_VERSION"));
    encoder.add_text_chunk("Software".into(), software).map_err(|e| e.to_string())?;
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(data).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Write a PNG atomically (see `png_bytes`).
pub fn save_png(path: &Path, width: u32, height: u32, alpha: bool, data: &[u8]) -> Result<(), ImageError> {
    let bytes = png_bytes(width, height, alpha, data)
        .map_err(|reason| ImageError::Encode { path: path.display().to_string(), reason })?;
    Ok(fileio::write_bytes(path, &bytes)?)
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
    Tonemap::new(exposure_stops).pixel(linear)
}

/// `tonemap_srgb8` at one exposure, for many pixels: the studio tone-maps
/// every changed tile of four panes each frame, and `powf` per channel made
/// the frames that took a whole pass cost tens of milliseconds.
#[derive(Clone, Copy, Debug)]
pub struct Tonemap {
    scale: f32,
}

/// Buckets of [0, 1] for `SrgbTable`: fine enough that one holds at most
/// one step of the 8-bit output (sRGB's steepest slope, 12.92·255 levels
/// per unit, is 0.8 levels a bucket).
const SRGB_BUCKETS: usize = 4096;

/// The 8-bit sRGB code of v ∈ [0, 1] as the formula gives it, found by
/// table: `start[b]` is the code at the start of bucket b, and `step[k]`
/// the smallest v whose code is k + 1 (found by bisection on the formula,
/// so the table and the formula agree exactly, tested below).
struct SrgbTable {
    start: [u8; SRGB_BUCKETS],
    step: [f32; 256],
}

fn srgb8_by_formula(v: f32) -> u8 {
    (srgb_encode(v) * 255.0 + 0.5) as u8
}

#[inline]
fn srgb_bucket(v: f32) -> usize {
    ((v * (SRGB_BUCKETS - 1) as f32) as usize).min(SRGB_BUCKETS - 1)
}

static SRGB_TABLE: std::sync::LazyLock<SrgbTable> = std::sync::LazyLock::new(|| {
    let mut step = [f32::INFINITY; 256];
    for (k, step) in step.iter_mut().enumerate().take(255) {
        // Non-negative floats order as their bits: bisect on those
        let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
        if srgb8_by_formula(1.0) as usize <= k {
            continue;
        }
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if srgb8_by_formula(f32::from_bits(mid)) as usize > k {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        *step = f32::from_bits(lo);
    }
    let mut start = [0u8; SRGB_BUCKETS];
    for (k, &at) in step.iter().enumerate().take(255) {
        if at.is_finite() {
            let first = srgb_bucket(at) + 1;
            start[first.min(SRGB_BUCKETS)..].iter_mut().for_each(|s| *s = (*s).max(k as u8 + 1));
        }
    }
    SrgbTable { start, step }
});

impl Tonemap {
    pub fn new(exposure_stops: f32) -> Self {
        Self { scale: exposure_stops.exp2() }
    }

    #[inline]
    pub fn pixel(&self, linear: [f32; 3]) -> [u8; 3] {
        let table = &*SRGB_TABLE;
        linear.map(|c| {
            let v = c * self.scale;
            if !v.is_finite() {
                return 0;
            }
            let v = v.clamp(0.0, 1.0);
            let mut code = table.start[srgb_bucket(v)];
            while v >= table.step[code as usize] {
                code += 1;
            }
            code
        })
    }
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
        let tonemap = Tonemap::new(exposure_stops);
        self.pixels
            .iter()
            .flat_map(|p| {
                let [r, g, b] = tonemap.pixel(*p);
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
        for y in 0..height {
            for x in 0..width {
                out.pixels[(y * width + x) as usize] = self.block_mean(x, y, factor);
            }
        }
        out
    }

    /// The mean of the `factor × factor` block at block (x, y): pixel (x, y)
    /// of `downsample(factor)`.
    pub fn block_mean(&self, x: u32, y: u32, factor: u32) -> [f32; 3] {
        let mut sum = [0.0f64; 3];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = self.get(x * factor + dx, y * factor + dy);
                (0..3).for_each(|c| sum[c] += p[c] as f64);
            }
        }
        let weight = 1.0 / (factor * factor) as f64;
        sum.map(|s| (s * weight) as f32)
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

    /// `.png`: tone-mapped sRGB 8-bit; `.exr`: linear 32-bit float. Written
    /// atomically: a failed save leaves whatever was at `path` as it was.
    pub fn save(&self, path: &Path, exposure_stops: f32) -> Result<(), ImageError> {
        let bytes = self
            .encode(ImageFormat::of(path)?, exposure_stops)
            .map_err(|reason| ImageError::Encode { path: path.display().to_string(), reason })?;
        Ok(fileio::write_bytes(path, &bytes)?)
    }

    /// The file's bytes in `format`.
    pub fn encode(&self, format: ImageFormat, exposure_stops: f32) -> Result<Vec<u8>, String> {
        if self.pixels.len() != self.width as usize * self.height as usize {
            return Err(format!("{} pixels for a {}×{} image", self.pixels.len(), self.width, self.height));
        }
        match format {
            ImageFormat::Png => {
                let tonemap = Tonemap::new(exposure_stops);
                let rgb: Vec<u8> = self.pixels.iter().flat_map(|p| tonemap.pixel(*p)).collect();
                png_bytes(self.width, self.height, false, &rgb)
            }
            ImageFormat::Exr => {
                use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage};
                let width = self.width as usize;
                let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                    let [r, g, b] = self.pixels[y * width + x];
                    (r, g, b)
                });
                let mut attributes = LayerAttributes::named("");
                attributes.software_name = Some(SIGNATURE.into());
                let layer = Layer::new((width, self.height as usize), attributes, Encoding::FAST_LOSSLESS, channels);
                let mut bytes = std::io::Cursor::new(Vec::new());
                Image::from_layer(layer).write().to_buffered(&mut bytes).map_err(|e| e.to_string())?;
                Ok(bytes.into_inner())
            }
        }
    }

    /// Load a linear EXR (references) or an 8-bit image decoded from sRGB;
    /// only a regular file, and no larger than the largest image the
    /// program renders (`limits::IMAGE_PIXELS`).
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let name = path.display().to_string();
        let decode = |reason: String| ImageError::Decode { path: name.clone(), reason };
        let most_bytes = limits::IMAGE_PIXELS * 16 + (1 << 20);
        let file = fileio::open_regular(path, most_bytes)?;
        let mut reader = image::ImageReader::new(std::io::BufReader::new(file))
            .with_guessed_format()
            .map_err(|e| decode(e.to_string()))?;
        let mut bounds = image::Limits::default();
        bounds.max_image_width = Some(limits::IMAGE_SIDE.max);
        bounds.max_image_height = Some(limits::IMAGE_SIDE.max);
        bounds.max_alloc = Some(most_bytes);
        reader.limits(bounds);
        let decoded = reader.decode().map_err(|e| decode(e.to_string()))?;
        let is_exr = ImageFormat::of(path).is_ok_and(|f| f == ImageFormat::Exr);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tonemap_known_points() {
        assert_eq!(tonemap_srgb8([0.0, 1.0, 0.5], 0.0), [0, 255, 188]);
        assert_eq!(tonemap_srgb8([0.25, 2.0, f32::NAN], 1.0), [188, 255, 0]);
        assert_eq!(tonemap_srgb8([-1.0, f32::INFINITY, 0.0], 0.0), [0, 0, 0]);
    }

    /// The table gives the formula's code for every float in [0, 1] at the
    /// codes' edges (each step and its neighbours) and on a fine grid, and
    /// each bucket holds at most one step.
    #[test]
    fn the_srgb_table_is_the_formula() {
        let table = &*SRGB_TABLE;
        let tonemap = Tonemap::new(0.0);
        let code = |v: f32| tonemap.pixel([v; 3])[0];
        let edges = table.step.iter().filter(|s| s.is_finite()).flat_map(|&s| [s.next_down(), s, s.next_up()]);
        let grid = (0..=2_000_000).map(|i| i as f32 / 2_000_000.0);
        for v in edges.chain(grid).filter(|v| (0.0..=1.0).contains(v)) {
            assert_eq!(code(v), srgb8_by_formula(v), "at {v:e}");
        }
        for window in table.step[..255].windows(2) {
            assert!(srgb_bucket(window[0]) < srgb_bucket(window[1]), "two steps in one bucket at {window:?}");
        }
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
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
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

    #[test]
    fn saved_images_carry_the_signature_and_refuse_a_wrong_size() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        let img = LinearImage::new(5, 4);
        for name in ["s.png", "s.exr"] {
            img.save(&dir.join(name), 0.0).unwrap();
            assert!(fileio::replaceable(&dir.join(name), &[SIGNATURE.as_bytes()]).unwrap(), "{name}");
        }
        let broken = LinearImage { width: 5, height: 5, ..img };
        for name in ["b.png", "b.exr"] {
            assert!(matches!(broken.save(&dir.join(name), 0.0), Err(ImageError::Encode { .. })), "{name}");
            assert!(!dir.join(name).exists(), "{name}");
        }
    }
}
