//! A hash grid over photons for SPPM's gather: the photons within a radius
//! of a point that arrive at its front. Cells are as wide as the widest
//! radius asked for, so a query touches at most 3×3×3 of them; the photons
//! are sorted by their cell's bucket (a counting sort, linear time) into
//! flat arrays by coordinate, which a query scans eight at a time.
//!
//! Chosen over the kd-tree by measurement: at SPPM's radii a query finds
//! hundreds of photons, and the kd walk pays a branch and a dependent load
//! for each, where the grid pays for a few more candidates, tested eight to
//! an instruction. Its sums are its own (the order of the photons differs),
//! the same on every CPU: without AVX2 the scalar scan keeps eight partial
//! sums as the lanes do.

use glam::Vec3;
use rayon::prelude::*;

use super::record::Photon;
#[cfg(target_arch = "x86_64")]
use crate::render::world::lanes;
use crate::render::world::lanes::{F8, LANES};

/// What a gather found: the photons' summed power, and how many.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrontSum {
    pub power: Vec3,
    pub count: u32,
}

pub struct PhotonGrid {
    origin: Vec3,
    inverse_cell: f32,
    /// The number of buckets less one (a power of two less one).
    mask: u32,
    /// Bucket b holds photons `starts[b]..starts[b + 1]` of the arrays below.
    starts: Vec<u32>,
    /// Positions, incoming directions and powers, one array per coordinate,
    /// sorted by bucket and padded with `LANES` zeros so that eight photons
    /// load at once from any start.
    position: [Vec<f32>; 3],
    incoming: [Vec<f32>; 3],
    power: [Vec<f32>; 3],
    /// Scan with AVX2 (false: the scalar scan, which sums the same bits).
    lanes: bool,
}

/// Photons per block of the columns filled in parallel.
const BLOCK: usize = 1 << 14;

/// Up to this many buckets a query lists on the stack.
const FEW: usize = 27;

/// The buckets a query touches, each once, in increasing order.
enum Touched {
    Few([u32; FEW], usize),
    Many(Vec<u32>),
    /// More cells than buckets: every photon is a candidate.
    All,
}

impl PhotonGrid {
    /// The grid of `photons` for queries of radius up to `cell` (larger
    /// radii are answered too, touching more cells).
    pub fn build(photons: &[Photon], cell: f32) -> Self {
        #[cfg(target_arch = "x86_64")]
        let lanes = lanes::supported();
        #[cfg(not(target_arch = "x86_64"))]
        let lanes = true;
        Self::build_scanning(photons, cell, lanes)
    }

    fn build_scanning(photons: &[Photon], cell: f32, lanes: bool) -> Self {
        let cell = if cell.is_finite() && cell > 0.0 { cell } else { 1.0 };
        let lowest = photons.iter().fold(Vec3::splat(f32::INFINITY), |m, p| m.min(p.position));
        let buckets = photons.len().next_power_of_two();
        let padded = || vec![0.0; photons.len() + LANES];
        let mut grid = Self {
            origin: if lowest.is_finite() { lowest } else { Vec3::ZERO },
            inverse_cell: 1.0 / cell,
            mask: (buckets - 1) as u32,
            starts: vec![0; buckets + 1],
            position: [padded(), padded(), padded()],
            incoming: [padded(), padded(), padded()],
            power: [padded(), padded(), padded()],
            lanes,
        };
        let bucket_of: Vec<u32> = photons.par_iter().map(|p| grid.bucket(grid.cell_of(p.position))).collect();
        for &b in &bucket_of {
            grid.starts[b as usize + 1] += 1;
        }
        for b in 0..buckets {
            grid.starts[b + 1] += grid.starts[b];
        }
        // Which photon goes where, then the columns filled in order: written
        // photon by photon at their places, nine columns would take a cache
        // miss each
        let mut next = grid.starts[..buckets].to_vec();
        let mut order = vec![0u32; photons.len()];
        for (photon, &b) in bucket_of.iter().enumerate() {
            order[next[b as usize] as usize] = photon as u32;
            next[b as usize] += 1;
        }
        let [px, py, pz] = &mut grid.position;
        let [ix, iy, iz] = &mut grid.incoming;
        let [pr, pg, pb] = &mut grid.power;
        let mut columns: Vec<_> =
            [px, py, pz, ix, iy, iz, pr, pg, pb].into_iter().map(|c| c[..photons.len()].chunks_mut(BLOCK)).collect();
        let blocks: Vec<Vec<&mut [f32]>> =
            (0..photons.len().div_ceil(BLOCK)).map(|_| columns.iter_mut().flat_map(|c| c.next()).collect()).collect();
        blocks.into_par_iter().zip(order.par_chunks(BLOCK)).for_each(|(mut block, order)| {
            for (k, &photon) in order.iter().enumerate() {
                let photon = &photons[photon as usize];
                let incoming = photon.incoming_direction();
                let values = [
                    photon.position.x,
                    photon.position.y,
                    photon.position.z,
                    incoming.x,
                    incoming.y,
                    incoming.z,
                    photon.power[0],
                    photon.power[1],
                    photon.power[2],
                ];
                for (column, value) in block.iter_mut().zip(values) {
                    column[k] = value;
                }
            }
        });
        grid
    }

    pub fn len(&self) -> usize {
        self.position[0].len() - LANES
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The direction photon `i` (an index `gather_front` handed out) travels.
    pub fn incoming(&self, i: usize) -> Vec3 {
        Vec3::new(self.incoming[0][i], self.incoming[1][i], self.incoming[2][i])
    }

    /// Photon `i`'s power.
    pub fn power(&self, i: usize) -> Vec3 {
        Vec3::new(self.power[0][i], self.power[1][i], self.power[2][i])
    }

    /// The photons within `radius` of `point` (squared distance ≤ radius²,
    /// as the kd-tree's `for_each_within` takes them) that arrive at the
    /// front of `facing` (incoming · facing < 0): their summed power and
    /// count, and each one's index handed to `each`, in an order fixed by
    /// the photons and the query alone.
    pub fn gather_front(&self, point: Vec3, radius: f32, facing: Vec3, mut each: impl FnMut(usize)) -> FrontSum {
        if self.is_empty() || radius.is_nan() || radius < 0.0 {
            return FrontSum::default();
        }
        let touched = self.touched(point, radius);
        let query = Query { point, bound: radius * radius, facing };
        #[cfg(target_arch = "x86_64")]
        if self.lanes {
            // SAFETY: `lanes` is set only where the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.scan_avx2(&touched, &query, &mut each) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        if self.lanes {
            return self.scan_lanes(&touched, &query, &mut each);
        }
        self.scan_scalar(&touched, &query, &mut each)
    }

    fn cell_of(&self, p: Vec3) -> [i32; 3] {
        // Saturating casts: a point far outside lands in an edge cell, on
        // either side of the query as on the photons'
        let c = (p - self.origin) * self.inverse_cell;
        [floor(c.x), floor(c.y), floor(c.z)]
    }

    fn bucket(&self, cell: [i32; 3]) -> u32 {
        // The hash of Teschner et al. (2003), as SmallVCM's grid uses it
        ((cell[0] as u32).wrapping_mul(73_856_093)
            ^ (cell[1] as u32).wrapping_mul(19_349_663)
            ^ (cell[2] as u32).wrapping_mul(83_492_791))
            & self.mask
    }

    fn touched(&self, point: Vec3, radius: f32) -> Touched {
        // A photon the float test takes may lie a few ulps beyond the
        // radius, and p ± reach rounds: the box is widened for both
        let reach = radius * 1.001 + point.abs().max_element() * 1e-6;
        let (lo, hi) = (self.cell_of(point - reach), self.cell_of(point + reach));
        let span = |axis: usize| (hi[axis] as i64 - lo[axis] as i64 + 1) as u64;
        let cells = span(0).saturating_mul(span(1)).saturating_mul(span(2));
        if cells > self.mask as u64 + 1 {
            return Touched::All;
        }
        let list = |push: &mut dyn FnMut(u32)| {
            for x in lo[0] as i64..=hi[0] as i64 {
                for y in lo[1] as i64..=hi[1] as i64 {
                    for z in lo[2] as i64..=hi[2] as i64 {
                        push(self.bucket([x as i32, y as i32, z as i32]));
                    }
                }
            }
        };
        let dedup_len = |ids: &mut [u32]| {
            ids.sort_unstable();
            let mut len = 0;
            for i in 0..ids.len() {
                if i == 0 || ids[i] != ids[len - 1] {
                    ids[len] = ids[i];
                    len += 1;
                }
            }
            len
        };
        if cells as usize <= FEW {
            let (mut ids, mut len) = ([0; FEW], 0);
            list(&mut |b| {
                ids[len] = b;
                len += 1;
            });
            let len = dedup_len(&mut ids[..len]);
            Touched::Few(ids, len)
        } else {
            let mut ids = Vec::with_capacity(cells as usize);
            list(&mut |b| ids.push(b));
            let len = dedup_len(&mut ids);
            ids.truncate(len);
            Touched::Many(ids)
        }
    }

    /// The photon ranges of the touched buckets, empty ones left out.
    fn ranges<'a>(&'a self, touched: &'a Touched) -> impl Iterator<Item = (usize, usize)> + 'a {
        let ids: &[u32] = match touched {
            Touched::Few(ids, len) => &ids[..*len],
            Touched::Many(ids) => ids,
            Touched::All => &[],
        };
        let all = matches!(touched, Touched::All).then_some((0, self.len()));
        let listed = ids.iter().map(|&b| (self.starts[b as usize] as usize, self.starts[b as usize + 1] as usize));
        all.into_iter().chain(listed).filter(|(start, end)| start < end)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn scan_avx2(&self, touched: &Touched, query: &Query, each: &mut impl FnMut(usize)) -> FrontSum {
        self.scan_lanes(touched, query, each)
    }

    /// Eight photons at a time from the start of each range, lane `k`
    /// taking the photons `start + k`, `start + 8 + k`, …
    #[inline(always)]
    fn scan_lanes(&self, touched: &Touched, query: &Query, each: &mut impl FnMut(usize)) -> FrontSum {
        let point = [F8::splat(query.point.x), F8::splat(query.point.y), F8::splat(query.point.z)];
        let facing = [F8::splat(query.facing.x), F8::splat(query.facing.y), F8::splat(query.facing.z)];
        let (bound, zero) = (F8::splat(query.bound), F8::splat(0.0));
        let lane = F8::from_array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let mut sums = [zero; 3];
        let mut count = 0;
        for (start, end) in self.ranges(touched) {
            for i in (start..end).step_by(LANES) {
                // No closures here: they would be compiled without AVX2
                let x = point[0] - F8::load(eight(&self.position[0], i));
                let y = point[1] - F8::load(eight(&self.position[1], i));
                let z = point[2] - F8::load(eight(&self.position[2], i));
                let distance2 = x * x + y * y + z * z;
                let cosine = F8::load(eight(&self.incoming[0], i)) * facing[0]
                    + F8::load(eight(&self.incoming[1], i)) * facing[1]
                    + F8::load(eight(&self.incoming[2], i)) * facing[2];
                let inside = lane.lt(F8::splat((end - i).min(LANES) as f32));
                let taken = inside.and(distance2.le(bound)).and(cosine.lt(zero));
                sums[0] = sums[0] + taken.select(F8::load(eight(&self.power[0], i)), zero);
                sums[1] = sums[1] + taken.select(F8::load(eight(&self.power[1], i)), zero);
                sums[2] = sums[2] + taken.select(F8::load(eight(&self.power[2], i)), zero);
                count += taken.bits().count_ones();
                for k in taken.lanes() {
                    each(i + k);
                }
            }
        }
        FrontSum {
            power: Vec3::new(
                lane_total(sums[0].to_array()),
                lane_total(sums[1].to_array()),
                lane_total(sums[2].to_array()),
            ),
            count,
        }
    }

    /// `scan_lanes` one photon at a time, with the same eight partial sums.
    fn scan_scalar(&self, touched: &Touched, query: &Query, each: &mut impl FnMut(usize)) -> FrontSum {
        let mut sums = [[0.0f32; LANES]; 3];
        let mut count = 0;
        for (start, end) in self.ranges(touched) {
            for i in start..end {
                let position = Vec3::new(self.position[0][i], self.position[1][i], self.position[2][i]);
                let taken = (query.point - position).length_squared() <= query.bound
                    && self.incoming(i).dot(query.facing) < 0.0;
                let power = self.power(i);
                for (axis, sum) in sums.iter_mut().enumerate() {
                    sum[(i - start) % LANES] += if taken { power[axis] } else { 0.0 };
                }
                if taken {
                    count += 1;
                    each(i);
                }
            }
        }
        FrontSum { power: Vec3::from_array(sums.map(lane_total)), count }
    }
}

struct Query {
    point: Vec3,
    bound: f32,
    facing: Vec3,
}

/// ⌊x⌋, saturating: `f32::floor` is a libm call on x86-64 without SSE4.1.
#[inline(always)]
fn floor(x: f32) -> i32 {
    let t = x as i32;
    t.saturating_sub(((t as f32) > x) as i32)
}

#[inline(always)]
fn eight(v: &[f32], i: usize) -> &[f32; LANES] {
    v[i..i + LANES].try_into().expect("the arrays are padded by LANES")
}

fn lane_total(lanes: [f32; LANES]) -> f32 {
    lanes.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// Photons on two walls and a floor (as SPPM stores them) and in the
    /// air, with random directions and powers.
    fn photons(n: usize, scale: f32, seed: u64) -> Vec<Photon> {
        let mut s = Sampler::new(0, 0, seed);
        (0..n)
            .map(|i| {
                let (u, v) = (s.next_f32() * scale, s.next_f32() * scale);
                let position = match i % 4 {
                    0 => Vec3::new(u, 0.0, v),
                    1 => Vec3::new(0.0, u, v),
                    2 => Vec3::new(u, v, scale),
                    _ => Vec3::new(u, v, s.next_f32() * scale),
                };
                let z = 2.0 * s.next_f32() - 1.0;
                let phi = std::f32::consts::TAU * s.next_f32();
                let r = (1.0 - z * z).max(0.0).sqrt();
                let incoming = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                Photon::new(position, incoming, [s.next_f32(), s.next_f32() * 2.0, 0.5])
            })
            .collect()
    }

    /// What the grid must find, by brute force over the photons: the same
    /// float tests, so the very same photons.
    fn brute_force(photons: &[Photon], point: Vec3, radius: f32, facing: Vec3) -> Vec<[u32; 6]> {
        let mut found: Vec<[u32; 6]> = (photons.iter())
            .filter(|p| {
                (point - p.position).length_squared() <= radius * radius && p.incoming_direction().dot(facing) < 0.0
            })
            .map(|p| key(p.position, Vec3::from_array(p.power)))
            .collect();
        found.sort_unstable();
        found
    }

    fn key(position: Vec3, power: Vec3) -> [u32; 6] {
        let (a, b) = (position.to_array(), power.to_array());
        [a[0], a[1], a[2], b[0], b[1], b[2]].map(f32::to_bits)
    }

    fn gathered(grid: &PhotonGrid, point: Vec3, radius: f32, facing: Vec3) -> (FrontSum, Vec<usize>) {
        let mut indices = Vec::new();
        let sum = grid.gather_front(point, radius, facing, |i| indices.push(i));
        (sum, indices)
    }

    fn position(grid: &PhotonGrid, i: usize) -> Vec3 {
        Vec3::new(grid.position[0][i], grid.position[1][i], grid.position[2][i])
    }

    /// Every query, each kind of bucket list (a few cells, many, all of
    /// them), finds exactly the brute force's photons, its count is theirs
    /// and its power their sum.
    #[test]
    fn a_gather_finds_the_photons_brute_force_finds() {
        let photons = photons(4000, 2.0, 7);
        let mut s = Sampler::new(1, 0, 7);
        for cell in [0.05, 0.2, 3.0] {
            let grid = PhotonGrid::build(&photons, cell);
            assert_eq!(grid.len(), photons.len());
            for query in 0..300 {
                let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.4 - 0.2;
                // Up to the cell (SPPM's queries), then well beyond it
                let radius = s.next_f32() * cell * if query % 3 == 0 { 4.0 } else { 1.0 };
                let facing = Vec3::new(s.next_f32() - 0.5, s.next_f32() - 0.5, s.next_f32() - 0.5).normalize();
                let expected = brute_force(&photons, point, radius, facing);
                let (sum, indices) = gathered(&grid, point, radius, facing);
                let mut found: Vec<[u32; 6]> =
                    indices.iter().map(|&i| key(position(&grid, i), grid.power(i))).collect();
                found.sort_unstable();
                assert_eq!(found, expected, "cell {cell}, query {query}: {point} within {radius}");
                assert_eq!(sum.count as usize, expected.len());
                let total = indices.iter().fold(glam::DVec3::ZERO, |t, &i| t + grid.power(i).as_dvec3());
                assert!((sum.power.as_dvec3() - total).abs().max_element() <= 1e-5 * total.max_element().max(1.0));
            }
        }
    }

    /// Photons a hair inside and outside the radius along each axis, far
    /// from the origin where coordinates round coarsely (smallpt's room sits
    /// at ~100, its walls at 1e5): the box around the query must not lose
    /// the ones the float test takes.
    #[test]
    fn photons_on_the_rim_of_the_radius_are_not_lost() {
        for centre in [Vec3::new(50.0, 40.0, 80.0), Vec3::new(1e5, -3e4, 7.0), Vec3::new(0.001, 0.0, 0.0)] {
            let radius = 0.37f32;
            let mut photons = Vec::new();
            for axis in 0..3 {
                for side in [1.0f32, -1.0] {
                    // The floats around where the rim crosses the axis
                    let rim = centre[axis] + side * radius;
                    for ulps in -4i32..=4 {
                        let mut position = centre;
                        position[axis] = f32::from_bits((rim.to_bits() as i32 + ulps) as u32);
                        let power = [ulps as f32 + 5.0, axis as f32, side];
                        photons.push(Photon::new(position, -Vec3::Y, power));
                    }
                }
            }
            // Cells exactly the radius, as SPPM's first pass makes them
            let grid = PhotonGrid::build(&photons, radius);
            let expected = brute_force(&photons, centre, radius, Vec3::Y);
            assert!(!expected.is_empty() && expected.len() < photons.len(), "the rim splits the photons");
            let (sum, indices) = gathered(&grid, centre, radius, Vec3::Y);
            let mut found: Vec<[u32; 6]> = indices.iter().map(|&i| key(position(&grid, i), grid.power(i))).collect();
            found.sort_unstable();
            assert_eq!(found, expected, "around {centre}");
            assert_eq!(sum.count as usize, expected.len());
        }
    }

    /// The lanes and the scalar scan hand out the same photons in the same
    /// order and sum the same bits, so an image does not depend on the CPU.
    #[test]
    fn the_lanes_and_the_scalar_scan_agree_bit_for_bit() {
        assert!(crate::render::world::lanes::supported(), "this test runs where the lanes do");
        let photons = photons(3000, 2.0, 11);
        let lanes = PhotonGrid::build_scanning(&photons, 0.15, true);
        let scalar = PhotonGrid::build_scanning(&photons, 0.15, false);
        let mut s = Sampler::new(2, 0, 11);
        let mut nonempty = 0;
        for _ in 0..400 {
            let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0;
            let radius = s.next_f32() * 0.3;
            let facing = Vec3::new(s.next_f32() - 0.5, s.next_f32() - 0.5, s.next_f32() - 0.5).normalize();
            let (a, b) = (gathered(&lanes, point, radius, facing), gathered(&scalar, point, radius, facing));
            assert_eq!(a.0.count, b.0.count);
            assert_eq!(a.0.power.to_array().map(f32::to_bits), b.0.power.to_array().map(f32::to_bits));
            assert_eq!(a.1, b.1);
            nonempty += (a.0.count > 0) as u32;
        }
        assert!(nonempty > 100, "{nonempty} queries found photons");
    }

    #[test]
    fn no_photons_or_no_radius_gathers_nothing() {
        let empty = PhotonGrid::build(&[], 0.5);
        assert_eq!(empty.gather_front(Vec3::ZERO, 1.0, Vec3::Y, |_| panic!()), FrontSum::default());
        let photons = photons(100, 1.0, 3);
        for cell in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            // A cell no radius gives falls back to a usable one
            let grid = PhotonGrid::build(&photons, cell);
            let (sum, _) = gathered(&grid, Vec3::splat(0.5), 10.0, Vec3::Y);
            assert_eq!(sum.count as usize, brute_force(&photons, Vec3::splat(0.5), 10.0, Vec3::Y).len());
        }
        let grid = PhotonGrid::build(&photons, 0.2);
        for radius in [f32::NAN, -0.1] {
            assert_eq!(grid.gather_front(Vec3::splat(0.5), radius, Vec3::Y, |_| panic!()), FrontSum::default());
        }
        // Cells beyond i32 on either side (saturated), radii beyond any cell
        for far in [Vec3::splat(1e30), Vec3::new(-1e30, 0.5, -3e9)] {
            for radius in [0.3, 1e30, f32::MAX] {
                let found = grid.gather_front(far, radius, Vec3::Y, |_| {});
                assert_eq!(found.count as usize, brute_force(&photons, far, radius, Vec3::Y).len());
            }
        }
    }
}
