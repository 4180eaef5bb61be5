//! SPPM's gather: the photons within a radius of a point that arrive at its
//! front, from a hash grid of the pass's photons (`cells::PointGrid`) with
//! their incoming directions and powers in columns beside the positions,
//! scanned eight at a time. Cells are as wide as the widest radius, so a
//! query touches 3×3×3 of them (four along an axis where its box, padded
//! for rounding, reaches just past a third cell: rarely).
//!
//! Its sums are its own (the photons come in another order than the
//! kd-tree's), the same on every CPU: without AVX2 the scalar scan keeps
//! eight partial sums as the lanes do.

use glam::Vec3;

use super::cells::{eight, fill_columns, PointGrid, Touched, FEW};
use super::record::Photon;
use crate::render::world::lanes::{F8, LANES};

/// What a gather found: the photons' summed power, and how many.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrontSum {
    pub power: Vec3,
    pub count: u32,
}

pub struct PhotonGrid {
    points: PointGrid,
    /// Incoming directions and powers, one column per coordinate, in the
    /// points' order and padded as their columns are.
    incoming: [Vec<f32>; 3],
    power: [Vec<f32>; 3],
}

impl PhotonGrid {
    /// The grid of `photons` for queries of radius up to `cell` (larger
    /// radii are answered too, touching more cells).
    /// Scanned eight at a time where the points' grid tests them so
    /// (`PointGrid::lanes`), else by the scalar scan, which sums the same bits.
    pub fn build(photons: &[Photon], cell: f32) -> Self {
        let points = PointGrid::build(photons, |p| p.position, cell);
        let padded = || vec![0.0; photons.len() + LANES];
        let mut grid = Self { points, incoming: [padded(), padded(), padded()], power: [padded(), padded(), padded()] };
        let [ix, iy, iz] = &mut grid.incoming;
        let [pr, pg, pb] = &mut grid.power;
        fill_columns(&grid.points.order, [ix, iy, iz, pr, pg, pb], photons, |photon| {
            let (d, p) = (photon.incoming_direction(), photon.power);
            [d.x, d.y, d.z, p[0], p[1], p[2]]
        });
        grid
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
    /// as `PointGrid::for_each_within` takes them) that arrive at the
    /// front of `facing` (incoming · facing < 0): their summed power and
    /// count, and each one's index handed to `each`, in an order fixed by
    /// the photons and the query alone.
    pub fn gather_front(&self, point: Vec3, radius: f32, facing: Vec3, mut each: impl FnMut(usize)) -> FrontSum {
        let mut few = [(0, 0); FEW];
        let Some(touched) = self.points.touched(point, radius, &mut few) else { return FrontSum::default() };
        let query = Query { point, bound: radius * radius, facing };
        #[cfg(target_arch = "x86_64")]
        if self.points.lanes {
            // SAFETY: `lanes` is set only where the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { self.scan_avx2(&touched, &query, &mut each) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        if self.points.lanes {
            return self.scan_lanes(&touched, &query, &mut each);
        }
        self.scan_scalar(&touched, &query, &mut each)
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
        for (start, end) in self.points.ranges(touched) {
            for i in (start..end).step_by(LANES) {
                // No closures here: they would be compiled without AVX2
                let x = point[0] - F8::load(eight(&self.points.position[0], i));
                let y = point[1] - F8::load(eight(&self.points.position[1], i));
                let z = point[2] - F8::load(eight(&self.points.position[2], i));
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
        for (start, end) in self.points.ranges(touched) {
            for i in start..end {
                let taken = (query.point - self.points.position_of(i)).length_squared() <= query.bound
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

fn lane_total(lanes: [f32; LANES]) -> f32 {
    lanes.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::integrators::photon_map::cells::tests::scattered;
    use crate::render::world::rng::Sampler;

    /// Photons where `scattered` puts points, random directions and powers.
    fn photons(n: usize, scale: f32, seed: u64) -> Vec<Photon> {
        let mut s = Sampler::new(3, 0, seed);
        (scattered(n, scale, seed).into_iter())
            .map(|position| {
                let z = 2.0 * s.next_f32() - 1.0;
                let phi = std::f32::consts::TAU * s.next_f32();
                let r = (1.0 - z * z).max(0.0).sqrt();
                let incoming = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                Photon::new(position, incoming, [s.next_f32(), s.next_f32() * 2.0, 0.5])
            })
            .collect()
    }

    fn query(s: &mut Sampler, scale: f32, radius: f32) -> (Vec3, f32, Vec3) {
        let point = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * scale;
        let facing = Vec3::new(s.next_f32() - 0.5, s.next_f32() - 0.5, s.next_f32() - 0.5).normalize();
        (point, s.next_f32() * radius, facing)
    }

    fn gathered(grid: &PhotonGrid, (point, radius, facing): (Vec3, f32, Vec3)) -> (FrontSum, Vec<usize>) {
        let mut indices = Vec::new();
        let sum = grid.gather_front(point, radius, facing, |i| indices.push(i));
        (sum, indices)
    }

    /// A gather takes the photons within the radius (by the same float
    /// test as brute force) that arrive at the front, and sums their power.
    #[test]
    fn a_gather_takes_the_photons_in_range_at_the_front_and_sums_their_power() {
        let photons = photons(4000, 2.0, 7);
        let grid = PhotonGrid::build(&photons, 0.2);
        let mut s = Sampler::new(1, 0, 7);
        let mut taken = 0;
        for _ in 0..300 {
            let (point, radius, facing) = query(&mut s, 2.0, 0.3);
            let expected: Vec<&Photon> = (photons.iter())
                .filter(|p| {
                    (point - p.position).length_squared() <= radius * radius && p.incoming_direction().dot(facing) < 0.0
                })
                .collect();
            let (sum, indices) = gathered(&grid, (point, radius, facing));
            let key =
                |position: Vec3, power: Vec3| [position.to_array(), power.to_array()].map(|a| a.map(f32::to_bits));
            let mut found: Vec<_> = indices.iter().map(|&i| key(grid.points.position_of(i), grid.power(i))).collect();
            let mut wanted: Vec<_> = expected.iter().map(|p| key(p.position, Vec3::from_array(p.power))).collect();
            found.sort_unstable();
            wanted.sort_unstable();
            assert_eq!(found, wanted);
            assert_eq!(sum.count as usize, expected.len());
            let total = expected.iter().fold(glam::DVec3::ZERO, |t, p| t + Vec3::from_array(p.power).as_dvec3());
            assert!((sum.power.as_dvec3() - total).abs().max_element() <= 1e-5 * total.max_element().max(1.0));
            taken += expected.len();
        }
        assert!(taken > 1000, "{taken} photons taken in all");
    }

    /// The lanes and the scalar scan hand out the same photons in the same
    /// order and sum the same bits, so an image does not depend on the CPU.
    #[test]
    fn the_lanes_and_the_scalar_scan_agree_bit_for_bit() {
        assert!(crate::render::world::lanes::supported(), "this test runs where the lanes do");
        let photons = photons(3000, 2.0, 11);
        let lanes = PhotonGrid::build(&photons, 0.15);
        let mut scalar = PhotonGrid::build(&photons, 0.15);
        scalar.points.lanes = false;
        let mut s = Sampler::new(2, 0, 11);
        let mut nonempty = 0;
        for _ in 0..400 {
            let q = query(&mut s, 2.0, 0.3);
            let (a, b) = (gathered(&lanes, q), gathered(&scalar, q));
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
        let grid = PhotonGrid::build(&photons(100, 1.0, 3), 0.2);
        for radius in [f32::NAN, -0.1] {
            assert_eq!(grid.gather_front(Vec3::splat(0.5), radius, Vec3::Y, |_| panic!()), FrontSum::default());
        }
    }
}
