//! A hash grid over points, for queries within a radius: cells of a chosen
//! width, each hashed to a bucket, the points counting-sorted by bucket
//! (`reorder::by_key`, linear time) into one column per coordinate. A query
//! lists the buckets its radius box touches, each once, as runs (a row of
//! cells along x hashes to consecutive buckets), and tests each run's
//! stretch of points eight at a time. SPPM's photon grid (`grid`) and
//! VCM's merges (`bidir::merging`) keep what they read of each point beside
//! the columns, in the same order (`in_grid_order_into`), so a query reads
//! nothing out of sequence.
//!
//! Chosen over the kd-tree by measurement for both: an SPPM query finds
//! hundreds of photons, for each of which the kd walk pays a branch and a
//! dependent load; a VCM query finds one or two light vertices, after a walk
//! of ~28 nodes that miss the cache, where the grid reads a few buckets.

use glam::Vec3;
use rayon::prelude::*;

use crate::render::integrators::reorder::{by_key, prefetch, PREFETCH_AHEAD};
use crate::render::world::lanes::{self, F8, LANES};

/// Points per block of the columns filled in parallel.
const BLOCK: usize = 1 << 14;

/// Up to this many runs of buckets a query lists on the stack, two a row
/// along x (one where the buckets wrap past the last): 4×4 rows, so
/// neither SPPM's queries (3×3 rows, four along an axis where the padded
/// box reaches past a third) nor VCM's (1 to 4) allocate.
pub(super) const FEW: usize = 64;

pub struct PointGrid {
    origin: Vec3,
    inverse_cell: f32,
    /// The number of buckets less one (a power of two less one).
    mask: u32,
    /// Bucket b holds points `starts[b]..starts[b + 1]` of the columns.
    starts: Vec<u32>,
    /// Coordinates by axis, sorted by bucket and padded with `LANES` zeros
    /// so that eight points load at once from any start.
    pub(super) position: [Vec<f32>; 3],
    /// Each sorted point's index in the points the grid was built from.
    pub(super) order: Vec<u32>,
    /// Test points eight at a time, with AVX2 on x86-64 (false: one at a
    /// time, the same slots; SPPM's grid scans alike).
    pub(super) lanes: bool,
}

/// Buckets `first..=last`: a row of cells along x, whose buckets follow
/// one another (`bucket`), so their points lie in one stretch.
pub(super) type Run = (u32, u32);

/// The buckets a query touches, each once, as runs in increasing order,
/// none touching the next.
pub(super) enum Touched<'a> {
    /// Listed in room on the caller's stack: returned by value, the list
    /// itself would be copied once per query.
    Few(&'a [Run]),
    Many(Vec<Run>),
    /// More cells than buckets: every point is a candidate.
    All,
}

impl PointGrid {
    /// The grid of `points`, each at `position(point)`, in cells `cell`
    /// wide (any radius is answered; wider ones touch more cells).
    pub fn build<T: Sync>(points: &[T], position: impl Fn(&T) -> Vec3 + Sync, cell: f32) -> Self {
        let count = points.len();
        let cell = if cell.is_finite() && cell > 0.0 { cell } else { 1.0 };
        let lowest = points.iter().fold(Vec3::splat(f32::INFINITY), |m, p| m.min(position(p)));
        let buckets = count.next_power_of_two();
        let mut grid = Self {
            // Half a cell below the lowest point: from the lowest point
            // itself, the floor and walls at the points' least coordinates
            // lay on cell borders, and every query on them touched the
            // cells on both sides (gap-room's VCM: 3.87 buckets a query,
            // 2.89 from half a cell lower)
            origin: if lowest.is_finite() { lowest - cell * 0.5 } else { Vec3::ZERO },
            inverse_cell: 1.0 / cell,
            mask: (buckets - 1) as u32,
            starts: Vec::new(),
            position: std::array::from_fn(|_| vec![0.0; count + LANES]),
            order: Vec::new(),
            lanes: lanes::supported(),
        };
        let bucket_of: Vec<u32> = points.par_iter().map(|p| grid.bucket(grid.cell_of(position(p)))).collect();
        // Which point goes where, then the columns filled in order: written
        // point by point at their places, each column would miss the cache
        (grid.starts, grid.order) = by_key(&bucket_of, buckets);
        let [x, y, z] = &mut grid.position;
        fill_columns(&grid.order, [x, y, z], points, |p| position(p).to_array());
        grid
    }

    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The index of every point with squared distance ≤ radius² from
    /// `point` (a point exactly on the radius is in), in an order
    /// fixed by the points and the query alone.
    pub fn for_each_within(&self, point: Vec3, radius: f32, mut f: impl FnMut(u32)) {
        self.for_each_slot_within(point, radius, |slot| f(self.order[slot]));
    }

    /// `for_each_within`'s points, each named by its slot in the grid's
    /// order (where `in_grid_order_into` put its values), not by its index.
    pub fn for_each_slot_within(&self, point: Vec3, radius: f32, mut f: impl FnMut(usize)) {
        let mut few = [(0, 0); FEW];
        let Some(touched) = self.touched(point, radius, &mut few) else { return };
        let bound = radius * radius;
        #[cfg(target_arch = "x86_64")]
        if self.lanes {
            // SAFETY: `lanes` is set only where the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.slots_within_avx2(&touched, point, bound, &mut f) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        if self.lanes {
            return self.slots_within_lanes(&touched, point, bound, &mut f);
        }
        for (start, end) in self.ranges(&touched) {
            for slot in start..end {
                if (point - self.position_of(slot)).length_squared() <= bound {
                    f(slot);
                }
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn slots_within_avx2(&self, touched: &Touched, point: Vec3, bound: f32, f: &mut impl FnMut(usize)) {
        self.slots_within_lanes(touched, point, bound, f)
    }

    /// The scalar test (the same float operations) eight points at a
    /// time, the slots handed out in the same order: a VCM query tests a
    /// few dozen points for one or two.
    #[inline(always)]
    fn slots_within_lanes(&self, touched: &Touched, point: Vec3, bound: f32, f: &mut impl FnMut(usize)) {
        let (px, py, pz) = (F8::splat(point.x), F8::splat(point.y), F8::splat(point.z));
        let bound = F8::splat(bound);
        let lane = F8::from_array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        // Every bucket's first points asked for at once, not one bucket's
        // after another's: a merge's few buckets each miss the cache
        if let Touched::Few(runs) = touched {
            for &(first, _) in *runs {
                let start = self.starts[first as usize] as usize;
                prefetch(&self.position[0][start]);
                prefetch(&self.position[1][start]);
                prefetch(&self.position[2][start]);
            }
        }
        for (start, end) in self.ranges(touched) {
            for i in (start..end).step_by(LANES) {
                // No closures here: they would be compiled without AVX2
                let x = px - F8::load(eight(&self.position[0], i));
                let y = py - F8::load(eight(&self.position[1], i));
                let z = pz - F8::load(eight(&self.position[2], i));
                let inside = lane.lt(F8::splat((end - i).min(LANES) as f32));
                for k in inside.and((x * x + y * y + z * z).le(bound)).lanes() {
                    f(i + k);
                }
            }
        }
    }

    /// `values` (one per point, in the points' order) in the grid's order,
    /// into `out` (its memory kept from pass to pass): slot k holds point
    /// `order[k]`'s, so a query reads its points' values in sequence, where
    /// by index each would be a cache miss.
    pub fn in_grid_order_into<T: Copy + Send + Sync>(&self, values: &[T], out: &mut Vec<T>) {
        let order = &self.order;
        out.clear();
        out.par_extend((0..order.len()).into_par_iter().map(|k| {
            if let Some(&ahead) = order.get(k + PREFETCH_AHEAD) {
                prefetch(&values[ahead as usize]);
            }
            values[order[k] as usize]
        }));
    }

    /// Sorted point `i`'s position.
    pub(super) fn position_of(&self, i: usize) -> Vec3 {
        Vec3::new(self.position[0][i], self.position[1][i], self.position[2][i])
    }

    fn cell_of(&self, p: Vec3) -> [i32; 3] {
        // Saturating: a point far outside lands in an edge cell, on either
        // side of the query as on the grid's
        let c = (p - self.origin) * self.inverse_cell;
        [floor(c.x), floor(c.y), floor(c.z)]
    }

    fn bucket(&self, cell: [i32; 3]) -> u32 {
        // Linear in x: a cell's neighbours along x are the next buckets, so
        // a query's cells share cache lines and their points lie side by
        // side, where the scrambling hash of Teschner et al. that SmallVCM
        // uses scatters them
        (cell[0] as u32)
            .wrapping_add((cell[1] as u32).wrapping_mul(19_349_663))
            .wrapping_add((cell[2] as u32).wrapping_mul(83_492_791))
            & self.mask
    }

    /// The lowest and highest cells within `radius` of `point`; None
    /// where no point can be.
    #[inline(always)]
    fn cell_box(&self, point: Vec3, radius: f32) -> Option<([i32; 3], [i32; 3])> {
        if self.is_empty() || radius.is_nan() || radius < 0.0 {
            return None;
        }
        // A point the float test takes may lie an ulp beyond the radius
        // (squares rounding alike), and p ± reach rounds: the box is
        // widened for both
        let reach = radius * 1.001 + point.abs().max_element() * 1e-6;
        Some((self.cell_of(point - reach), self.cell_of(point + reach)))
    }

    /// The buckets within `radius` of `point`; None where no point can be.
    /// Listed by rows along x, not cell by cell: a query's 27 cells (SPPM)
    /// were 27 buckets to sort, and 27 stretches of points each ending in
    /// a part-filled group of eight; its 9 rows are 9 runs and 9 stretches.
    #[inline(always)]
    pub(super) fn touched<'a>(&self, point: Vec3, radius: f32, few: &'a mut [Run; FEW]) -> Option<Touched<'a>> {
        let (lo, hi) = self.cell_box(point, radius)?;
        let span = |axis: usize| (hi[axis] as i64 - lo[axis] as i64 + 1) as u64;
        let cells = span(0).saturating_mul(span(1)).saturating_mul(span(2));
        if cells > self.mask as u64 + 1 {
            return Some(Touched::All);
        }
        // A row's buckets follow one another, past the last to the first
        let last_of_row = span(0) as u32 - 1;
        let list = |push: &mut dyn FnMut(Run)| {
            for y in lo[1] as i64..=hi[1] as i64 {
                for z in lo[2] as i64..=hi[2] as i64 {
                    let first = self.bucket([lo[0], y as i32, z as i32]);
                    match first.checked_add(last_of_row).filter(|&last| last <= self.mask) {
                        Some(last) => push((first, last)),
                        None => {
                            push((first, self.mask));
                            push((0, last_of_row - (self.mask - first) - 1));
                        }
                    }
                }
            }
        };
        // Two runs a row at most
        let rows = span(1) * span(2);
        Some(if rows as usize * 2 <= FEW {
            let mut len = 0;
            list(&mut |run| {
                few[len] = run;
                len += 1;
            });
            let len = sort_merge(&mut few[..len]);
            Touched::Few(&few[..len])
        } else {
            let mut runs = Vec::with_capacity(rows as usize * 2);
            list(&mut |run| runs.push(run));
            let len = sort_merge(&mut runs);
            runs.truncate(len);
            Touched::Many(runs)
        })
    }

    /// The point ranges of the touched runs, empty ones left out.
    pub(super) fn ranges<'a>(&'a self, touched: &'a Touched) -> impl Iterator<Item = (usize, usize)> + 'a {
        let runs: &[Run] = match touched {
            Touched::Few(runs) => runs,
            Touched::Many(runs) => runs,
            Touched::All => &[],
        };
        let all = matches!(touched, Touched::All).then_some((0, self.len()));
        let listed = runs
            .iter()
            .map(|&(first, last)| (self.starts[first as usize] as usize, self.starts[last as usize + 1] as usize));
        all.into_iter().chain(listed).filter(|(start, end)| start < end)
    }
}

/// The eight values of a padded column from `i`.
#[inline(always)]
pub(super) fn eight(v: &[f32], i: usize) -> &[f32; LANES] {
    v[i..i + LANES].try_into().expect("the arrays are padded by LANES")
}

/// Columns filled in sorted order, block by block in parallel: column c of
/// sorted point k is `values(&records[order[k]])[c]`, the records asked
/// for ahead (a fifth of the fill's time at the bench's SPPM).
pub(super) fn fill_columns<T: Sync, const C: usize>(
    order: &[u32],
    columns: [&mut Vec<f32>; C],
    records: &[T],
    values: impl Fn(&T) -> [f32; C] + Sync,
) {
    let mut chunks: Vec<_> = columns.into_iter().map(|c| c[..order.len()].chunks_mut(BLOCK)).collect();
    let blocks: Vec<Vec<&mut [f32]>> =
        (0..order.len().div_ceil(BLOCK)).map(|_| chunks.iter_mut().flat_map(|c| c.next()).collect()).collect();
    blocks.into_par_iter().enumerate().for_each(|(b, mut block)| {
        let (start, end) = (b * BLOCK, ((b + 1) * BLOCK).min(order.len()));
        for (k, &point) in order[start..end].iter().enumerate() {
            if let Some(&ahead) = order.get(start + k + PREFETCH_AHEAD) {
                prefetch(&records[ahead as usize]);
            }
            for (column, value) in block.iter_mut().zip(values(&records[point as usize])) {
                column[k] = value;
            }
        }
    });
}

/// Sort `runs` and join those that overlap or meet (rows whose cells hash
/// to the same buckets), each joined run to the front; how many there are.
fn sort_merge(runs: &mut [Run]) -> usize {
    runs.sort_unstable();
    let mut len = 0;
    for i in 0..runs.len() {
        let (first, last) = runs[i];
        if len > 0 && first <= runs[len - 1].1.saturating_add(1) {
            runs[len - 1].1 = runs[len - 1].1.max(last);
        } else {
            runs[len] = (first, last);
            len += 1;
        }
    }
    len
}

/// ⌊x⌋, saturating: `f32::floor` is a libm call on x86-64 without SSE4.1.
#[inline(always)]
fn floor(x: f32) -> i32 {
    let t = x as i32;
    t.saturating_sub(((t as f32) > x) as i32)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// Points on two walls and a floor and in the air.
    pub(in crate::render::integrators::photon_map) fn scattered(n: usize, scale: f32, seed: u64) -> Vec<Vec3> {
        let mut s = Sampler::new(0, 0, seed);
        (0..n)
            .map(|i| {
                let (u, v) = (s.next_f32() * scale, s.next_f32() * scale);
                match i % 4 {
                    0 => Vec3::new(u, 0.0, v),
                    1 => Vec3::new(0.0, u, v),
                    2 => Vec3::new(u, v, scale),
                    _ => Vec3::new(u, v, s.next_f32() * scale),
                }
            })
            .collect()
    }

    fn brute_force(points: &[Vec3], point: Vec3, radius: f32) -> Vec<u32> {
        (0..points.len() as u32).filter(|&i| (point - points[i as usize]).length_squared() <= radius * radius).collect()
    }

    fn within(grid: &PointGrid, point: Vec3, radius: f32) -> Vec<u32> {
        let mut found = Vec::new();
        grid.for_each_within(point, radius, |i| found.push(i));
        found.sort_unstable();
        found
    }

    /// Every query, each kind of bucket list (a few cells, many, all of
    /// them), finds exactly the brute force's points, each once.
    #[test]
    fn a_query_finds_the_points_brute_force_finds() {
        let points = scattered(4000, 2.0, 7);
        let mut s = Sampler::new(1, 0, 7);
        for cell in [0.05, 0.2, 3.0] {
            let grid = PointGrid::build(&points, |&p| p, cell);
            for query in 0..300 {
                let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.4 - 0.2;
                // Up to the cell (SPPM's and VCM's queries), then well beyond it
                let radius = s.next_f32() * cell * if query % 3 == 0 { 4.0 } else { 1.0 };
                assert_eq!(within(&grid, point, radius), brute_force(&points, point, radius), "cell {cell}, {point}");
            }
        }
    }

    /// On a grid of a few buckets, rows of cells wrap past the last bucket
    /// and fall on each other's buckets: the runs a query lists are still
    /// sorted and apart, and it finds each point once.
    #[test]
    fn runs_that_wrap_and_overlap_are_joined() {
        let mut s = Sampler::new(5, 0, 17);
        let (mut wrapped, mut joined) = (0, 0);
        for n in [3, 6, 9, 17] {
            let points = scattered(n, 2.0, n as u64);
            let grid = PointGrid::build(&points, |&p| p, 0.3);
            for _ in 0..300 {
                let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.4 - 0.2;
                let radius = s.next_f32() * 0.5;
                assert_eq!(within(&grid, point, radius), brute_force(&points, point, radius), "{n} points, {point}");
                let mut few = [(0, 0); FEW];
                if let Some(Touched::Few(runs)) = grid.touched(point, radius, &mut few) {
                    assert!(runs.iter().all(|&(first, last)| first <= last && last <= grid.mask));
                    assert!(runs.windows(2).all(|w| w[1].0 > w[0].1 + 1), "apart: {runs:?}");
                    // Rows of more cells than the runs' buckets overlapped or wrapped
                    let (lo, hi) = grid.cell_box(point, radius).expect("a box");
                    let span = |axis: usize| (hi[axis] - lo[axis] + 1) as u32;
                    let buckets: u32 = runs.iter().map(|&(first, last)| last - first + 1).sum();
                    joined += (buckets < span(0) * span(1) * span(2)) as u32;
                    wrapped += (grid.bucket(lo) + span(0) - 1 > grid.mask) as u32;
                }
            }
        }
        assert!(wrapped >= 10 && joined >= 50, "wrapped {wrapped}, joined {joined}");
    }

    /// A small query on the floor the points lie lowest on (a VCM merge
    /// on gap-room's floor) touches that floor's cells alone, not also the
    /// empty ones below it.
    #[test]
    fn a_query_on_the_lowest_floor_touches_one_layer_of_cells() {
        let points = scattered(4000, 2.0, 5);
        let cell = 0.2;
        let grid = PointGrid::build(&points, |&p| p, cell);
        let mut s = Sampler::new(2, 0, 5);
        for _ in 0..200 {
            // Well inside a cell along x and z: only y could add cells
            let inside = |s: &mut Sampler| s.next_f32().mul_add(0.4, 0.3) + (s.next_f32() * 9.0).floor();
            let (x, z) = (inside(&mut s), inside(&mut s));
            let point = Vec3::new(grid.origin.x + x * cell, 0.0, grid.origin.z + z * cell);
            let mut few = [(0, 0); FEW];
            let Some(Touched::Few(runs)) = grid.touched(point, cell * 0.25, &mut few) else { panic!("no bucket list") };
            assert_eq!(runs.len(), 1, "{point}");
            assert_eq!(runs[0].0, runs[0].1, "one cell along x: {point}");
        }
    }

    /// A query's slots name, through the values `in_grid_order_into` put there,
    /// the points its indices name, in the same order.
    #[test]
    fn slots_name_the_points_indices_name() {
        let points = scattered(3000, 2.0, 11);
        let grid = PointGrid::build(&points, |&p| p, 0.1);
        let (mut index_at, mut position_at) = (Vec::new(), Vec::new());
        grid.in_grid_order_into(&(0..points.len() as u32).collect::<Vec<_>>(), &mut index_at);
        grid.in_grid_order_into(&points, &mut position_at);
        let mut s = Sampler::new(2, 0, 11);
        let mut found = 0;
        for _ in 0..200 {
            let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0;
            let (mut by_index, mut by_slot) = (Vec::new(), Vec::new());
            grid.for_each_within(point, 0.15, |i| by_index.push(i));
            grid.for_each_slot_within(point, 0.15, |slot| {
                assert_eq!(position_at[slot], grid.position_of(slot));
                by_slot.push(index_at[slot]);
            });
            assert_eq!(by_slot, by_index);
            found += by_index.len();
        }
        assert!(found > 200, "the queries find points ({found})");
    }

    /// Eight at a time and one at a time, a query hands out the same slots
    /// in the same order (a merge's sum is then the same on every CPU).
    #[test]
    fn the_lanes_and_the_scalar_test_hand_out_the_same_slots() {
        assert!(lanes::supported(), "this test runs where the lanes do");
        let points = scattered(3000, 2.0, 13);
        let eight = PointGrid::build(&points, |&p| p, 0.1);
        let mut one = PointGrid::build(&points, |&p| p, 0.1);
        one.lanes = false;
        let mut s = Sampler::new(4, 0, 13);
        let mut found = 0;
        for _ in 0..300 {
            let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0;
            let radius = s.next_f32() * 0.3;
            let (mut a, mut b) = (Vec::new(), Vec::new());
            eight.for_each_slot_within(point, radius, |slot| a.push(slot));
            one.for_each_slot_within(point, radius, |slot| b.push(slot));
            assert_eq!(a, b);
            found += a.len();
        }
        assert!(found > 1000, "the queries find points ({found})");
    }

    /// Points within ±4 ulps of where the rim crosses each axis, around
    /// centres where coordinates round coarsely (smallpt's room sits at
    /// ~100, its walls at 1e5): the box around the query must not lose the
    /// ones the float test takes.
    #[test]
    fn points_on_the_rim_of_the_radius_are_not_lost() {
        for centre in [Vec3::new(50.0, 40.0, 80.0), Vec3::new(1e5, -3e4, 7.0), Vec3::new(0.001, 0.0, 0.0)] {
            let radius = 0.37f32;
            let mut points = Vec::new();
            for axis in 0..3 {
                for side in [1.0f32, -1.0] {
                    let rim = centre[axis] + side * radius;
                    for ulps in -4i32..=4 {
                        let mut p = centre;
                        p[axis] = f32::from_bits((rim.to_bits() as i32 + ulps) as u32);
                        points.push(p);
                    }
                }
            }
            // Cells exactly the radius, as SPPM's first pass makes them
            let grid = PointGrid::build(&points, |&p| p, radius);
            let expected = brute_force(&points, centre, radius);
            assert!(!expected.is_empty() && expected.len() < points.len(), "the rim splits the points");
            assert_eq!(within(&grid, centre, radius), expected, "around {centre}");
        }
    }

    #[test]
    fn no_points_or_no_radius_finds_nothing() {
        let empty = PointGrid::build(&[] as &[Vec3], |&p| p, 0.5);
        empty.for_each_within(Vec3::ZERO, 1.0, |_| panic!("no points"));
        let points = scattered(100, 1.0, 3);
        for cell in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            // A width no radius gives falls back to a usable one
            let grid = PointGrid::build(&points, |&p| p, cell);
            assert_eq!(within(&grid, Vec3::splat(0.5), 10.0), brute_force(&points, Vec3::splat(0.5), 10.0));
        }
        let grid = PointGrid::build(&points, |&p| p, 0.2);
        for radius in [f32::NAN, -0.1] {
            grid.for_each_within(Vec3::splat(0.5), radius, |_| panic!("no radius"));
        }
        // Cells beyond i32 on either side (saturated), radii beyond any cell
        for far in [Vec3::splat(1e30), Vec3::new(-1e30, 0.5, -3e9)] {
            for radius in [0.3, 1e30, f32::MAX] {
                assert_eq!(within(&grid, far, radius), brute_force(&points, far, radius));
            }
        }
    }
}
