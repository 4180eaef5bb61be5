//! The film: what passes accumulate into. The image is cut into tiles,
//! rendered centre first, each owning its sums, so parallel passes need no
//! locks. Methods that trace from the lights splat to any pixel: their
//! splats are collected per chunk of work and added in chunk order, so the
//! image never depends on which thread ran what.

use rayon::prelude::*;

use crate::render::image::LinearImage;
use crate::render::world::camera::TileRect;
use crate::scene::Rgb;

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

/// The ε of relMSE's (x − r)²/(r² + ε): it keeps dark pixels from
/// dominating. The engine's own noise estimate and the metrics share it.
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// Per-pixel sums of one tile, in f64 so thousands of passes add up exactly
/// enough.
#[derive(Clone, Debug)]
pub struct FilmTile {
    pub rect: TileRect,
    pub sums: Vec<[f64; 3]>,
    /// The odd passes' sums alone, where the film keeps halves (`Film::new`):
    /// with `sums`, two independent half estimates, whose difference
    /// measures the estimate's noise (`variance`).
    pub odd_sums: Vec<[f64; 3]>,
    /// Passes added to every pixel of the tile.
    pub samples: u32,
}

/// An estimated relMSE and its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseEstimate {
    pub rel_mse: f64,
    pub standard_error: f64,
}

/// Sums of per-pixel terms, to make a mean and its standard error of.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TermSums {
    pub sum: f64,
    pub squares: f64,
    pub count: u64,
}

impl TermSums {
    pub fn push(&mut self, term: f64) {
        self.sum += term;
        self.squares += term * term;
        self.count += 1;
    }

    pub fn add(&mut self, other: &TermSums) {
        self.sum += other.sum;
        self.squares += other.squares;
        self.count += other.count;
    }

    /// The terms' mean and its standard error (None without two terms).
    pub fn estimate(&self) -> Option<NoiseEstimate> {
        if self.count < 2 {
            return None;
        }
        let n = self.count as f64;
        let mean = self.sum / n;
        let variance = ((self.squares - n * mean * mean) / (n - 1.0)).max(0.0);
        Some(NoiseEstimate { rel_mse: mean, standard_error: (variance / n).sqrt() })
    }
}

/// `n` zero sums, written here rather than asked of the allocator as zeroed
/// memory (`vec![0.0; n]`, calloc), which leaves fresh pages unmapped: a
/// pass would first read each as the shared zero page, and its write after
/// that copies the page and stops the other render threads to flush their
/// view of it (a TLB shootdown, slow in a VM), page by page.
/// The zero goes through `black_box`: seen as zero, the optimiser may turn
/// the allocation and its filling back into one calloc.
fn written_zeros(n: usize) -> Vec<[f64; 3]> {
    let mut sums = Vec::with_capacity(n);
    sums.resize(n, std::hint::black_box([0.0; 3]));
    sums
}

/// Where one pass adds to a tile: every pass's sums, and on an odd pass
/// the odd passes' too, where the film keeps halves (`FilmTile::pass_sums`).
pub struct PassSums<'a> {
    sums: &'a mut [[f64; 3]],
    odd_sums: Option<&'a mut [[f64; 3]]>,
}

impl PassSums<'_> {
    #[inline]
    pub fn add(&mut self, i: usize, value: Rgb) {
        add_to(&mut self.sums[i], value);
        if let Some(odd_sums) = &mut self.odd_sums {
            add_to(&mut odd_sums[i], value);
        }
    }
}

#[inline]
fn add_to(sum: &mut [f64; 3], value: Rgb) {
    for c in 0..3 {
        sum[c] += value[c] as f64;
    }
}

impl FilmTile {
    pub fn new(rect: TileRect, halves: bool) -> Self {
        let odd_sums = if halves { written_zeros(rect.pixels()) } else { Vec::new() };
        Self { rect, sums: written_zeros(rect.pixels()), odd_sums, samples: 0 }
    }

    /// The tile's current estimate, row-major.
    pub fn mean(&self) -> Vec<[f32; 3]> {
        let scale = 1.0 / self.samples.max(1) as f64;
        self.sums.iter().map(|s| s.map(|c| (c * scale) as f32)).collect()
    }

    /// Add one value (a sample, or the splats' sum) to pixel `i` of the
    /// tile, in the pass that `samples` is about to count.
    #[inline]
    pub fn add(&mut self, i: usize, value: Rgb) {
        self.pass_sums().add(i, value);
    }

    /// Where the pass that `samples` is about to count adds, pixel by pixel.
    #[inline]
    pub fn pass_sums(&mut self) -> PassSums<'_> {
        let odd = self.samples % 2 == 1 && !self.odd_sums.is_empty();
        PassSums { sums: &mut self.sums, odd_sums: odd.then_some(&mut self.odd_sums) }
    }

    /// Each pixel's (mean, estimated variance of the mean), channel by
    /// channel, where the film keeps halves and has two passes: of n
    /// passes, n_o odd and n_e even, the halves' means differ by a quantity
    /// of variance σ²(1/n_e + 1/n_o), and the mean's is σ²/n, so
    /// (m_e − m_o)² n_e n_o / n² is an unbiased estimate of it.
    pub fn mean_and_variance(&self) -> Option<impl Iterator<Item = ([f64; 3], [f64; 3])> + '_> {
        let n = self.samples as f64;
        let odd = (self.samples / 2) as f64;
        let even = n - odd;
        if self.odd_sums.is_empty() || odd < 1.0 {
            return None;
        }
        let scale = even * odd / (n * n);
        Some(self.sums.iter().zip(&self.odd_sums).map(move |(sum, odd_sum)| {
            let mean = sum.map(|s| s / n);
            let variance = std::array::from_fn(|c| {
                let (m_odd, m_even) = (odd_sum[c] / odd, (sum[c] - odd_sum[c]) / even);
                (m_even - m_odd).powi(2) * scale
            });
            (mean, variance)
        }))
    }

    /// The estimated variance of every pixel's mean (`mean_and_variance`).
    pub fn variance(&self) -> Option<Vec<[f32; 3]>> {
        Some(self.mean_and_variance()?.map(|(_, v)| v.map(|c| c as f32)).collect())
    }

    /// The tile's terms of the estimate's own relMSE: variance/(m² + ε) per
    /// pixel and channel (an unbiased method's error against the converged
    /// image it tends to, as a denoiser estimates noise). m is the median of
    /// the pixel's 3×3 neighbourhood in the tile, not its own mean: a
    /// firefly inflates its own mean as much as its variance and would
    /// weigh itself down (with its own mean, the Cornell box's error at 64
    /// spp reads a third of the truth; with the median, within half again,
    /// and on the side of too much, tests/references.rs).
    pub fn noise_terms(&self) -> TermSums {
        let mut terms = TermSums::default();
        let Some(pixels) = self.mean_and_variance() else { return terms };
        let (means, variances): (Vec<[f64; 3]>, Vec<[f64; 3]>) = pixels.unzip();
        let (width, height) = (self.rect.width as usize, self.rect.height as usize);
        let mut around = Vec::with_capacity(9);
        for (i, variance) in variances.iter().enumerate() {
            let (x, y) = (i % width, i / width);
            for c in 0..3 {
                around.clear();
                for ny in y.saturating_sub(1)..(y + 2).min(height) {
                    around.extend((x.saturating_sub(1)..(x + 2).min(width)).map(|nx| means[ny * width + nx][c]));
                }
                let middle = around.len() / 2;
                let (_, &mut median, _) = around.select_nth_unstable_by(middle, f64::total_cmp);
                terms.push(variance[c] / (median * median + REL_MSE_EPSILON));
            }
        }
        terms
    }
}

/// A contribution to any pixel of the film (light tracing's camera
/// connections, BDPT's t = 1 strategies).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    pub x: u32,
    pub y: u32,
    pub value: Rgb,
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    tile_size: u32,
    pub tiles: Vec<FilmTile>,
    /// Which tile holds each cell of the tile grid (the tiles are sorted).
    tile_of_cell: Vec<u32>,
}

impl Film {
    /// A film of `width × height` in tiles of `tile_size`, keeping the odd
    /// passes apart where `halves` (for an estimate of its noise).
    pub fn new(width: u32, height: u32, tile_size: u32, halves: bool) -> Self {
        let tile_size = tile_size.max(1);
        // On every thread: writing the sums is most of the time it takes
        let tiles: Vec<FilmTile> =
            tile_layout(width, height, tile_size).into_par_iter().map(|rect| FilmTile::new(rect, halves)).collect();
        let columns = width.div_ceil(tile_size);
        let mut tile_of_cell = vec![0; (columns * height.div_ceil(tile_size)) as usize];
        for (i, tile) in tiles.iter().enumerate() {
            tile_of_cell[(tile.rect.y / tile_size * columns + tile.rect.x / tile_size) as usize] = i as u32;
        }
        Self { width, height, tile_size, tiles, tile_of_cell }
    }

    /// Add one pass's splats: `chunks` in the order the work was numbered
    /// (not the order threads finished it), each chunk's splats in order.
    /// Splats off the film are dropped.
    pub fn add_splats(&mut self, chunks: impl IntoIterator<Item = Vec<Splat>>) {
        let columns = self.width.div_ceil(self.tile_size);
        for splat in chunks.into_iter().flatten() {
            if splat.x >= self.width || splat.y >= self.height {
                continue;
            }
            let cell = splat.y / self.tile_size * columns + splat.x / self.tile_size;
            let tile = &mut self.tiles[self.tile_of_cell[cell as usize] as usize];
            let rect = tile.rect;
            tile.add(((splat.y - rect.y) * rect.width + splat.x - rect.x) as usize, splat.value);
        }
    }

    /// The odd passes' mean (the second, fourth… pass counted from 1),
    /// where the film keeps halves and has two passes.
    pub fn odd_image(&self) -> Option<LinearImage> {
        let odd_mean = |tile: &FilmTile| -> Option<Vec<[f32; 3]>> {
            let odd = tile.samples / 2;
            (!tile.odd_sums.is_empty() && odd >= 1)
                .then(|| tile.odd_sums.iter().map(|s| s.map(|c| (c / odd as f64) as f32)).collect())
        };
        let per_tile: Vec<Vec<[f32; 3]>> = self.tiles.iter().map(odd_mean).collect::<Option<_>>()?;
        Some(self.image(|i| per_tile[i].clone()))
    }

    /// Every pixel's estimated variance (`FilmTile::variance`), where the
    /// film keeps halves and has two passes.
    pub fn variance(&self) -> Option<LinearImage> {
        let per_tile: Option<Vec<Vec<[f32; 3]>>> = self.tiles.iter().map(FilmTile::variance).collect();
        let per_tile = per_tile?;
        Some(self.image(|i| per_tile[i].clone()))
    }

    /// The whole image from each tile's pixels (`tile_pixels(i)` row-major).
    pub fn image(&self, tile_pixels: impl Fn(usize) -> Vec<[f32; 3]>) -> LinearImage {
        let mut image = LinearImage::new(self.width, self.height);
        for (i, tile) in self.tiles.iter().enumerate() {
            for (k, pixel) in tile_pixels(i).into_iter().enumerate() {
                let (x, y) = tile.rect.pixel(k);
                image.pixels[(y * self.width + x) as usize] = pixel;
            }
        }
        image
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

    /// Splats land on their pixel whichever tile holds it, and the film does
    /// not depend on how the work was split into chunks, only on its order.
    #[test]
    fn splats_land_on_their_pixels_in_chunk_order() {
        let (w, h) = (70, 45);
        let mut splats = Vec::new();
        let mut state = 1u64;
        for _ in 0..5000 {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let (x, y) = ((state >> 33) as u32 % (w + 3), (state >> 13) as u32 % (h + 2));
            splats.push(Splat { x, y, value: Rgb::splat((state >> 40) as f32 / 1e6 + 1e-3) });
        }
        let mut whole = Film::new(w, h, 16, false);
        whole.add_splats([splats.clone()]);
        let mut chunked = Film::new(w, h, 16, false);
        chunked.add_splats(splats.chunks(37).map(<[Splat]>::to_vec));
        let mut expected = vec![[0.0f64; 3]; (w * h) as usize];
        for s in splats.iter().filter(|s| s.x < w && s.y < h) {
            let pixel = &mut expected[(s.y * w + s.x) as usize];
            (0..3).for_each(|c| pixel[c] += s.value[c] as f64);
        }
        for film in [&whole, &chunked] {
            for tile in &film.tiles {
                for (i, sum) in tile.sums.iter().enumerate() {
                    let (x, y) = tile.rect.pixel(i);
                    assert_eq!(*sum, expected[(y * w + x) as usize], "pixel ({x}, {y})");
                }
            }
        }
    }

    /// A new tile's sums are in memory, written: pages the allocator hands
    /// over unwritten (calloc's, `vec![0.0; n]`) would be read first by the
    /// first pass as the shared zero page, and the write after that stops
    /// the other render threads to flush it, page by page. Sums of 50 MB, so
    /// that glibc maps fresh pages for them however its threshold has moved.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_new_tiles_sums_are_in_memory_before_its_first_pass() {
        let rect = TileRect { x: 0, y: 0, width: 1448, height: 1448 };
        let tile = FilmTile::new(rect, false);
        let (resident, pages) = resident_pages(&tile.sums);
        assert_eq!(resident, pages, "{resident} of {pages} pages in memory");
    }

    /// How many of the pages `values` spans are in memory, of how many.
    #[cfg(target_os = "linux")]
    #[allow(unsafe_code)]
    fn resident_pages<T>(values: &[T]) -> (usize, usize) {
        // SAFETY: sysconf and mincore only read; mincore's range is whole
        // pages of one allocation, and `flags` has one byte a page.
        unsafe {
            let page = libc::sysconf(libc::_SC_PAGESIZE) as usize;
            let start = values.as_ptr() as usize / page * page;
            let end = (values.as_ptr() as usize + std::mem::size_of_val(values)).div_ceil(page) * page;
            let mut flags = vec![0u8; (end - start) / page];
            let status = libc::mincore(start as *mut libc::c_void, end - start, flags.as_mut_ptr());
            assert_eq!(status, 0, "mincore");
            (flags.iter().filter(|f| **f & 1 == 1).count(), flags.len())
        }
    }

    /// The halves' variance estimate is unbiased: for samples of known
    /// variance σ² (uniform on [0, a): a²/12), the mean over many pixels of
    /// the estimated variance of a pixel's mean is σ²/n within its standard
    /// error (each pixel's estimate is σ²/n·χ²₁: relative spread √2), for an
    /// odd number of passes (halves of unequal size) and an even one.
    #[test]
    fn halves_estimate_the_variance_of_the_mean_without_bias() {
        let rect = TileRect { x: 0, y: 0, width: 48, height: 48 };
        let mut state = 7u64;
        let mut uniform = move || {
            state = crate::render::world::rng::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let scale = |i: usize| 1.0 + (i % 5) as f64;
        for passes in [2u32, 7, 40] {
            let mut tile = FilmTile::new(rect, true);
            assert!(tile.mean_and_variance().is_none(), "no passes, no estimate");
            for _ in 0..passes {
                for i in 0..rect.pixels() {
                    let value = Rgb::new(uniform() as f32, uniform() as f32, uniform() as f32) * scale(i) as f32;
                    tile.add(i, value);
                }
                tile.samples += 1;
            }
            let mut ratios = TermSums::default();
            for (i, (mean, variance)) in tile.mean_and_variance().expect("two passes or more").enumerate() {
                let true_variance = scale(i).powi(2) / 12.0 / passes as f64;
                for c in 0..3 {
                    assert!((mean[c] / scale(i) - 0.5).abs() < 0.5, "a mean inside the samples' range");
                    ratios.push(variance[c] / true_variance);
                }
            }
            let estimate = ratios.estimate().unwrap();
            let z = (estimate.rel_mse - 1.0) / estimate.standard_error;
            assert!(z.abs() < 4.0, "{passes} passes: estimated/true variance {:.4} (z = {z:.2})", estimate.rel_mse);
        }
        let without_halves = FilmTile { samples: 4, ..FilmTile::new(rect, false) };
        assert!(without_halves.mean_and_variance().is_none());
    }
}
