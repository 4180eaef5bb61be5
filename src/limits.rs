//! Every bound on what a user types or a file holds, in one place: the CLI's
//! flags, scene files, photon-map headers and the studio's saved settings
//! all check against these, so no value can allocate without bound, start
//! unbounded threads or render forever. The README's "Known limits" lists
//! them.

use std::fmt;

/// An inclusive range a value must lie in (the lower end exclusive when
/// `above_min`); NaN lies in none.
#[derive(Clone, Copy, Debug)]
pub struct Limit<T> {
    pub min: T,
    pub max: T,
    pub above_min: bool,
}

/// A value outside its limit, said as a user reads it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("must be {range}, found {found}")]
pub struct OutOfRange {
    pub range: String,
    pub found: String,
}

impl<T: PartialOrd + Copy + fmt::Display> Limit<T> {
    pub const fn inclusive(min: T, max: T) -> Self {
        Self { min, max, above_min: false }
    }

    pub const fn above(min: T, max: T) -> Self {
        Self { min, max, above_min: true }
    }

    pub fn contains(&self, value: T) -> bool {
        let low = if self.above_min { value > self.min } else { value >= self.min };
        low && value <= self.max
    }

    pub fn check(&self, value: T) -> Result<T, OutOfRange> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(OutOfRange { range: self.to_string(), found: value.to_string() })
        }
    }

    /// Parse and check a command-line value (clap's `value_parser`).
    pub fn parse(&self, text: &str) -> Result<T, String>
    where
        T: std::str::FromStr,
        T::Err: fmt::Display,
    {
        let value: T = text.trim().parse().map_err(|e: T::Err| e.to_string())?;
        self.check(value).map_err(|e| e.to_string())
    }
}

impl<T: fmt::Display> fmt::Display for Limit<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.above_min {
            write!(f, "greater than {} and at most {}", self.min, self.max)
        } else {
            write!(f, "between {} and {}", self.min, self.max)
        }
    }
}

/// Width or height of an image, in pixels.
pub const IMAGE_SIDE: Limit<u32> = Limit::inclusive(1, 16_384);
/// Pixels in one image: 2²⁵ (8192 × 4096); the film keeps about 64 bytes
/// a pixel (sums, the odd passes' sums, the image), so at most about 2 GB.
pub const IMAGE_PIXELS: u64 = 1 << 25;
pub const SAMPLES_PER_PIXEL: Limit<u32> = Limit::inclusive(1, 1_000_000);
/// A wall-clock budget: up to a week.
pub const SECONDS: Limit<f64> = Limit::above(0.0, 604_800.0);
/// A time that may be none at all (0: do not).
pub const SECONDS_OR_NONE: Limit<f64> = Limit::inclusive(0.0, 604_800.0);
pub const EXPOSURE_STOPS: Limit<f32> = Limit::inclusive(-64.0, 64.0);
pub const MAX_DEPTH: Limit<u32> = Limit::inclusive(1, 1024);
/// Worker threads; 0 means one per core.
pub const THREADS: Limit<usize> = Limit::inclusive(0, 256);
/// Shards one render is split into (`render --shard`, `farm`).
pub const SHARDS: Limit<u32> = Limit::inclusive(1, 10_000);
pub const TILE_SIZE: Limit<u32> = Limit::inclusive(4, 512);
/// Photons emitted for one map, or in one SPPM pass (28 bytes each stored).
pub const PHOTONS: Limit<u32> = Limit::inclusive(0, 50_000_000);
pub const SPPM_PHOTONS: Limit<u32> = Limit::inclusive(1, 50_000_000);
/// Photons gathered per estimate (Jensen: fewer than 8 is noise).
pub const K_NEAREST: Limit<u32> = Limit::inclusive(8, 10_000);
pub const GATHER_RAYS: Limit<u32> = Limit::inclusive(1, 4096);
/// Radii, clamps and other lengths: finite and not negative.
pub const LENGTH: Limit<f32> = Limit::inclusive(0.0, f32::MAX);
/// A microfacet surface's α: 1 is already as rough as GGX surfaces are drawn.
pub const ROUGHNESS: Limit<f32> = Limit::inclusive(0.0, 1.0);
/// Each part of a metal's complex index, η and k (the measured metals' lie within 0.1–10).
pub const METAL_INDEX: Limit<f32> = Limit::inclusive(0.0, 100.0);
pub const SPPM_ALPHA: Limit<f32> = Limit::above(0.0, 1.0);
/// Photons stored in one map read from a file.
pub const STORED_PHOTONS: u64 = 200_000_000;
/// Scene files, the studio's state file and reference metadata.
pub const TEXT_FILE_BYTES: u64 = 16 << 20;
/// A mesh file (OBJ or PLY).
pub const MESH_FILE_BYTES: u64 = 256 << 20;
/// Triangles in one scene's meshes, all told.
pub const MESH_TRIANGLES: usize = 10_000_000;
/// Triangles a scene places, its meshes counted once a placement: each
/// placed triangle is compiled into the world (a mesh placed a thousand
/// times would otherwise ask for a thousand copies).
pub const PLACED_TRIANGLES: usize = 20_000_000;
/// The reference cache's size; the least recently used go beyond it.
pub const REFERENCE_CACHE_BYTES: u64 = 512 << 20;

/// The pixel count of `width × height`, refused beyond `IMAGE_PIXELS`.
pub fn check_image_size(width: u32, height: u32) -> Result<(), OutOfRange> {
    IMAGE_SIDE.check(width)?;
    IMAGE_SIDE.check(height)?;
    let pixels = width as u64 * height as u64;
    if pixels > IMAGE_PIXELS {
        return Err(OutOfRange {
            range: format!("at most {IMAGE_PIXELS} pixels (8192 × 4096)"),
            found: format!("{width} × {height} = {pixels}"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_are_in_and_beyond_them_is_out() {
        assert!(SAMPLES_PER_PIXEL.contains(1) && SAMPLES_PER_PIXEL.contains(1_000_000));
        assert!(!SAMPLES_PER_PIXEL.contains(0) && !SAMPLES_PER_PIXEL.contains(1_000_001));
        assert!(!SECONDS.contains(0.0) && SECONDS.contains(1e-3) && SECONDS.contains(604_800.0));
        for bad in [f64::NAN, f64::INFINITY, -1.0, 1e300] {
            assert!(!SECONDS.contains(bad), "{bad}");
        }
        assert!(!EXPOSURE_STOPS.contains(f32::NAN) && EXPOSURE_STOPS.contains(-64.0));
    }

    #[test]
    fn parse_names_the_range_and_the_value() {
        assert_eq!(SAMPLES_PER_PIXEL.parse("16"), Ok(16));
        assert_eq!(SAMPLES_PER_PIXEL.parse("0").unwrap_err(), "must be between 1 and 1000000, found 0");
        assert_eq!(SECONDS.parse("NaN").unwrap_err(), "must be greater than 0 and at most 604800, found NaN");
        assert!(THREADS.parse("-3").is_err() && THREADS.parse("ten").is_err());
    }

    #[test]
    fn image_size_bounds_each_side_and_the_total() {
        assert!(check_image_size(8192, 4096).is_ok());
        assert!(check_image_size(8192, 4097).is_err());
        assert!(check_image_size(16_384, 1).is_ok());
        assert!(check_image_size(0, 10).is_err() && check_image_size(16_385, 1).is_err());
        let message = check_image_size(100_000, 100_000).unwrap_err().to_string();
        assert!(message.contains("16384") && message.contains("100000"), "{message}");
    }
}
