//! The image cut into tiles, rendered centre first, each owning its own
//! accumulation buffer so parallel passes need no locks.

use crate::render::integrators::sppm::SppmPixel;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Tiles covering `width × height`, ordered by distance from the centre: the
/// part a user looks at sharpens first.
pub fn tile_layout(width: u32, height: u32, tile_size: u32) -> Vec<TileRect> {
    let size = tile_size.max(1);
    let mut tiles = Vec::new();
    for y in (0..height).step_by(size as usize) {
        for x in (0..width).step_by(size as usize) {
            tiles.push(TileRect { x, y, width: size.min(width - x), height: size.min(height - y) });
        }
    }
    let (cx, cy) = (width as f32 * 0.5, height as f32 * 0.5);
    let distance = |t: &TileRect| {
        let dx = t.x as f32 + t.width as f32 * 0.5 - cx;
        let dy = t.y as f32 + t.height as f32 * 0.5 - cy;
        dx * dx + dy * dy
    };
    tiles.sort_by(|a, b| distance(a).total_cmp(&distance(b)));
    tiles
}

/// Per-pixel sums of one tile, in f64 so thousands of passes add up exactly
/// enough.
#[derive(Clone, Debug)]
pub struct TileAccumulator {
    pub rect: TileRect,
    pub sums: Vec<[f64; 3]>,
    /// Samples (passes) added to every pixel of the tile.
    pub samples: u32,
    /// Progressive photon mapping's per-pixel state (empty otherwise).
    pub sppm: Vec<SppmPixel>,
}

impl TileAccumulator {
    pub fn new(rect: TileRect, sppm: bool) -> Self {
        let pixels = (rect.width * rect.height) as usize;
        Self {
            rect,
            sums: if sppm { Vec::new() } else { vec![[0.0; 3]; pixels] },
            samples: 0,
            sppm: if sppm { vec![SppmPixel::default(); pixels] } else { Vec::new() },
        }
    }

    /// The tile's current estimate, row-major.
    pub fn mean(&self) -> Vec<[f32; 3]> {
        if !self.sppm.is_empty() {
            return self.sppm.iter().map(|p| p.value(self.samples).to_array()).collect();
        }
        let scale = 1.0 / self.samples.max(1) as f64;
        self.sums.iter().map(|s| s.map(|c| (c * scale) as f32)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_every_pixel_once_centre_first() {
        let (w, h) = (100, 70);
        let tiles = tile_layout(w, h, 32);
        let mut covered = vec![0u8; (w * h) as usize];
        for t in &tiles {
            for y in t.y..t.y + t.height {
                for x in t.x..t.x + t.width {
                    covered[(y * w + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|c| *c == 1));
        let first = tiles[0];
        assert!(first.x <= 50 && 50 < first.x + first.width && first.y <= 35 && 35 < first.y + first.height);
    }
}
