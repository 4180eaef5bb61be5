//! A bounding volume hierarchy over any primitives given by their boxes:
//! binned surface-area-heuristic splits (Wald 2007), nodes in one array
//! with both children of a node side by side, at most `LEAF` primitives a
//! leaf where they can be split. A ray visits the nearer child first and
//! skips what lies beyond its nearest hit, so its cost grows with the
//! logarithm of the primitives, where the groups of four it replaces grow
//! with their number.
//!
//! The primitive test is the caller's: what a ray finds is what testing
//! every primitive in the order the traversal meets them finds, each
//! against the nearest hit so far.

use glam::Vec3;

use crate::geometry::{gamma, Ray};

/// Primitives a leaf holds once a split no longer pays.
const LEAF: usize = 4;

/// Bins the centroids are counted into along the split axis.
const BINS: usize = 12;

/// How deep the traversal's stack goes: the build splits no deeper.
const MAX_DEPTH: usize = 64;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// A leaf's first primitive in `order`, or an inner node's first child.
    start: u32,
    /// A leaf's count of primitives; 0 for an inner node.
    count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive indices, each leaf's a run of them.
    order: Vec<u32>,
}

/// A box: (low corner, high corner).
type Bounds = (Vec3, Vec3);

fn union((a_lo, a_hi): Bounds, (b_lo, b_hi): Bounds) -> Bounds {
    (a_lo.min(b_lo), a_hi.max(b_hi))
}

const EMPTY: Bounds = (Vec3::INFINITY, Vec3::NEG_INFINITY);

/// Half the surface area (what the heuristic compares); 0 for an empty box.
fn half_area((lo, hi): Bounds) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

impl Bvh {
    /// Over primitives with boxes `bounds` (index i for `bounds[i]`).
    pub fn new(bounds: &[Bounds]) -> Self {
        let centroids: Vec<Vec3> = bounds.iter().map(|(lo, hi)| (*lo + *hi) * 0.5).collect();
        let mut bvh = Bvh { nodes: Vec::with_capacity(2 * bounds.len()), order: (0..bounds.len() as u32).collect() };
        bvh.nodes.push(Node { lo: Vec3::ZERO, hi: Vec3::ZERO, start: 0, count: 0 });
        // (node, first, end, depth): ranges of `order` still to place
        let mut todo = vec![(0usize, 0usize, bounds.len(), 0usize)];
        while let Some((node, first, end, depth)) = todo.pop() {
            let range = &mut bvh.order[first..end];
            let (lo, hi) = range.iter().fold(EMPTY, |b, &i| union(b, bounds[i as usize]));
            bvh.nodes[node].lo = lo;
            bvh.nodes[node].hi = hi;
            let split = match range.len() > LEAF && depth + 1 < MAX_DEPTH {
                true => Self::split(range, bounds, &centroids, (lo, hi)),
                false => None,
            };
            let Some(middle) = split else {
                bvh.nodes[node].start = first as u32;
                bvh.nodes[node].count = (end - first) as u32;
                continue;
            };
            let left = bvh.nodes.len();
            bvh.nodes[node].start = left as u32;
            bvh.nodes.push(Node { lo, hi, start: 0, count: 0 });
            bvh.nodes.push(Node { lo, hi, start: 0, count: 0 });
            todo.push((left, first, first + middle, depth + 1));
            todo.push((left + 1, first + middle, end, depth + 1));
        }
        bvh
    }

    /// Sorts `range` about the cheapest split by the heuristic and says
    /// where its right part starts; `None` where a leaf is cheaper.
    fn split(range: &mut [u32], bounds: &[Bounds], centroids: &[Vec3], node: Bounds) -> Option<usize> {
        let (c_lo, c_hi) = range.iter().fold(EMPTY, |b, &i| union(b, (centroids[i as usize], centroids[i as usize])));
        let extent = c_hi - c_lo;
        let axis = extent.max_position();
        if extent[axis] <= 0.0 {
            // Every centroid in one place: halve by count once too many
            return (range.len() > 2 * LEAF).then_some(range.len() / 2);
        }
        let bin_of = |i: u32| {
            let at = (centroids[i as usize][axis] - c_lo[axis]) / extent[axis] * BINS as f32;
            (at as usize).min(BINS - 1)
        };
        let mut bins = [(EMPTY, 0usize); BINS];
        for &i in range.iter() {
            let bin = &mut bins[bin_of(i)];
            *bin = (union(bin.0, bounds[i as usize]), bin.1 + 1);
        }
        // The cost of each split between bins k and k + 1, from both ends
        let mut right = [(0.0f32, 0usize); BINS];
        let mut acc = (EMPTY, 0);
        for k in (1..BINS).rev() {
            acc = (union(acc.0, bins[k].0), acc.1 + bins[k].1);
            right[k] = (half_area(acc.0), acc.1);
        }
        let mut left = (EMPTY, 0);
        let mut best = (f32::INFINITY, 0);
        for k in 0..BINS - 1 {
            left = (union(left.0, bins[k].0), left.1 + bins[k].1);
            let (right_area, right_count) = right[k + 1];
            let cost = half_area(left.0) * left.1 as f32 + right_area * right_count as f32;
            if left.1 > 0 && right_count > 0 && cost < best.0 {
                best = (cost, k);
            }
        }
        // A leaf costs a test of each primitive; a split, a box test more
        let leaf = half_area(node) * range.len() as f32;
        if best.0 >= leaf && range.len() <= 2 * LEAF {
            return None;
        }
        if best.0 == f32::INFINITY {
            return Some(range.len() / 2);
        }
        // Partition: bins up to `best.1` to the left
        let mut middle = 0;
        for j in 0..range.len() {
            if bin_of(range[j]) <= best.1 {
                range.swap(j, middle);
                middle += 1;
            }
        }
        Some(middle)
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The ray's entry into `node`'s box if it meets it before `t_max`
    /// (the exit pushed out by the slab test's rounding, so no hit in the
    /// box is missed).
    #[inline(always)]
    fn enter(node: &Node, origin: Vec3, inverse: Vec3, t_max: f32) -> Option<f32> {
        let t0 = (node.lo - origin) * inverse;
        let t1 = (node.hi - origin) * inverse;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element() * (1.0 + 2.0 * gamma(3));
        (near <= far && near < t_max).then_some(near)
    }

    /// The nearest hit within (0, t_max) of `test` (given a primitive and
    /// the nearest hit so far, its hit nearer than that, with its t), and
    /// the primitive's index.
    #[inline]
    pub fn nearest<H>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<(f32, H)>,
    ) -> Option<(u32, H)> {
        if self.order.is_empty() {
            return None;
        }
        let (origin, inverse) = (ray.origin, ray.direction.recip());
        let mut best_t = t_max;
        let mut found = None;
        let mut stack = [0u32; MAX_DEPTH];
        let mut depth = 0;
        let mut node = 0usize;
        // A ray that misses the whole box tests nothing
        Self::enter(&self.nodes[0], origin, inverse, best_t)?;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                for &i in &self.order[n.start as usize..(n.start + n.count) as usize] {
                    if let Some((t, hit)) = test(i, best_t) {
                        best_t = t;
                        found = Some((i, hit));
                    }
                }
            } else {
                let (left, right) = (n.start as usize, n.start as usize + 1);
                let near_left = Self::enter(&self.nodes[left], origin, inverse, best_t);
                let near_right = Self::enter(&self.nodes[right], origin, inverse, best_t);
                match (near_left, near_right) {
                    (Some(l), Some(r)) => {
                        let (first, second) = if l <= r { (left, right) } else { (right, left) };
                        stack[depth] = second as u32;
                        depth += 1;
                        node = first;
                        continue;
                    }
                    (Some(_), None) => {
                        node = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = right;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Next on the stack, if the ray still meets it before its nearest hit
            loop {
                if depth == 0 {
                    return found;
                }
                depth -= 1;
                node = stack[depth] as usize;
                if Self::enter(&self.nodes[node], origin, inverse, best_t).is_some() {
                    break;
                }
            }
        }
    }

    /// Whether `test` (given a primitive) holds for any primitive whose box
    /// the ray meets within (0, t_max).
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32, mut test: impl FnMut(u32) -> bool) -> bool {
        if self.order.is_empty() {
            return false;
        }
        let (origin, inverse) = (ray.origin, ray.direction.recip());
        // Both children go on it: one more than the tree is deep
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let n = &self.nodes[stack[depth] as usize];
            if Self::enter(n, origin, inverse, t_max).is_none() {
                continue;
            }
            if n.count > 0 {
                if self.order[n.start as usize..(n.start + n.count) as usize].iter().any(|&i| test(i)) {
                    return true;
                }
            } else {
                stack[depth] = n.start;
                stack[depth + 1] = n.start + 1;
                depth += 2;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{intersect_triangle, Triangle};
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;

    /// Triangles of a rough sphere's surface, small ones in clusters and a
    /// few long slivers across it, some in one place (equal centroids).
    fn triangles(s: &mut Sampler, count: usize) -> Vec<Triangle> {
        let mut out = Vec::new();
        while out.len() < count {
            let center = uniform_sphere(s.next_2d()) * 3.0;
            let size = if out.len() % 17 == 0 { 4.0 } else { 0.2 };
            let corner = |s: &mut Sampler| center + (Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) - 0.5) * size;
            let triangle = Triangle::new(corner(s), corner(s), corner(s));
            out.push(triangle);
            if out.len() % 29 == 0 {
                // The same triangle again, and again
                out.push(triangle);
                out.push(triangle);
            }
        }
        out.truncate(count);
        out
    }

    fn bounds_of(triangles: &[Triangle]) -> Vec<Bounds> {
        (triangles.iter())
            .map(|t| {
                let [a, b, c] = t.vertices;
                (a.min(b.min(c)), a.max(b.max(c)))
            })
            .collect()
    }

    /// The hierarchy finds what testing every triangle in order finds: the
    /// same nearest t, and any hit exactly where there is one; every
    /// primitive is in one leaf.
    #[test]
    fn finds_what_testing_every_primitive_finds() {
        let mut s = Sampler::new(0, 0, 57);
        for count in [0usize, 1, 3, 5, 40, 300, 2000] {
            let list = triangles(&mut s, count);
            let bvh = Bvh::new(&bounds_of(&list));
            let mut leaves: Vec<u32> = bvh.order.clone();
            leaves.sort_unstable();
            assert_eq!(leaves, (0..count as u32).collect::<Vec<_>>());
            let (mut hits, mut misses) = (0, 0);
            for k in 0..3000 {
                let origin = uniform_sphere(s.next_2d()) * (1.0 + 6.0 * s.next_f32());
                let direction = match (k % 3, list.len()) {
                    // At a triangle's centroid, so these hit
                    (0, n) if n > 0 => (list[k % n].vertices.iter().sum::<Vec3>() / 3.0 - origin).normalize(),
                    _ => uniform_sphere(s.next_2d()),
                };
                let ray = Ray::new(origin, direction);
                let t_max = if k % 5 == 0 { 2.0 } else { f32::INFINITY };
                let mut expected: Option<(u32, f32)> = None;
                for (i, t) in list.iter().enumerate() {
                    if let Some(hit) = intersect_triangle(&ray, t, expected.map_or(t_max, |e| e.1)) {
                        expected = Some((i as u32, hit.t));
                    }
                }
                let got = bvh.nearest(&ray, t_max, |i, best| {
                    intersect_triangle(&ray, &list[i as usize], best).map(|hit| (hit.t, hit.t))
                });
                assert_eq!(got.map(|g| g.1), expected.map(|e| e.1), "{count} triangles, ray {ray:?}");
                let any = bvh.any_hit(&ray, t_max, |i| intersect_triangle(&ray, &list[i as usize], t_max).is_some());
                assert_eq!(any, expected.is_some());
                hits += expected.is_some() as u32;
                misses += expected.is_none() as u32;
            }
            if count >= 40 {
                assert!(hits > 500 && misses > 500, "{count}: {hits} hits, {misses} misses");
            }
        }
    }

    /// The build splits: a ray through a large scene tests a few leaves,
    /// not every primitive.
    #[test]
    fn a_ray_tests_few_of_many_primitives() {
        let mut s = Sampler::new(0, 0, 58);
        let list = triangles(&mut s, 20_000);
        let bvh = Bvh::new(&bounds_of(&list));
        let (mut tested, rays) = (0usize, 500);
        for _ in 0..rays {
            let ray = Ray::new(uniform_sphere(s.next_2d()) * 8.0, uniform_sphere(s.next_2d()));
            bvh.nearest(&ray, f32::INFINITY, |i, best| {
                tested += 1;
                intersect_triangle(&ray, &list[i as usize], best).map(|hit| (hit.t, ()))
            });
        }
        let mean = tested as f32 / rays as f32;
        assert!(mean < 0.02 * list.len() as f32, "{mean} triangles tested a ray, of {}", list.len());
        assert!(bvh.nodes.len() < 2 * list.len());
    }
}
