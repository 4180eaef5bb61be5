//! A bounding volume hierarchy over any primitives given by their boxes:
//! binned surface-area-heuristic splits (Wald 2007) built as a binary tree,
//! then flattened into eight-wide nodes (`widen`), at most `LEAF`
//! primitives a leaf where they can be split. A ray visits the nearer
//! children first and skips what lies beyond its nearest hit, so its cost
//! grows with the logarithm of the primitives, where the groups of four it
//! replaces grow with their number. Its time goes to waiting for memory,
//! node after node: eight children a node halve the levels four would
//! make, and the children a ray enters are asked for all at once.
//!
//! The primitive test is the caller's: what a ray finds is what testing
//! every primitive in the order the traversal meets them finds, each
//! against the nearest hit so far.

use glam::{Vec3, Vec4};

use crate::geometry::{gamma, Ray};

/// Primitives a leaf holds once a split no longer pays.
const LEAF: usize = 4;

/// Bins the centroids are counted into along each axis.
const BINS: usize = 16;

/// Below this depth the build splits at the median, not where the
/// heuristic would (on a scene built to make it peel off one primitive a
/// level): the halves keep the tree within `MAX_DEPTH` and every leaf at
/// most `2 * LEAF` primitives, whatever the scene.
const MEDIAN_DEPTH: usize = 32;

/// How deep the tree can be: 32 halvings more than `MEDIAN_DEPTH` leave
/// a leaf of any `u32` count of primitives.
const MAX_DEPTH: usize = MEDIAN_DEPTH + 32;

/// The traversal's stack: an eight-wide node is at least one binary level
/// below its parent, and each leaves at most seven children waiting.
const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// Children a node holds.
const WIDTH: usize = 8;

/// Asks the memory for the first `lines` cache lines of `what`: a hint,
/// which changes nothing but when the lines arrive.
#[inline(always)]
pub fn prefetch_lines<T>(what: &T, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for line in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let at = (what as *const T as *const i8).wrapping_add(64 * line);
        // SAFETY: SSE is part of x86-64, and a prefetch reads nothing
        #[allow(unsafe_code)]
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(at)
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (what, lines);
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// A leaf's first primitive in `order`, or an inner node's first child.
    start: u32,
    /// A leaf's count of primitives; 0 for an inner node.
    count: u32,
}

/// Eight children's boxes side by side, tested against a ray four at a
/// time (SSE, which every x86-64 has, where the scalar callers run): four
/// cache lines.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Wide {
    /// Per half (children 0–3, 4–7), per axis, each child's low and
    /// high bound.
    lo: [[Vec4; 3]; 2],
    hi: [[Vec4; 3]; 2],
    /// Per child: an inner node's index in `wide`, or a leaf's first
    /// primitive in `order`.
    start: [u32; WIDTH],
    /// Per child: a leaf's count of primitives (at most `2 * LEAF`, or
    /// what `map_leaves` made of it); 0 for an inner node.
    count: [u8; WIDTH],
    /// The children it has, a bit each.
    valid: u32,
}

impl Wide {
    const EMPTY: Wide =
        Wide { lo: [[Vec4::ZERO; 3]; 2], hi: [[Vec4::ZERO; 3]; 2], start: [0; WIDTH], count: [0; WIDTH], valid: 0 };
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// The binary tree as built, eight-wide (`widen`): what rays traverse.
    wide: Vec<Wide>,
    /// Primitive indices, each leaf's a run of them.
    order: Vec<u32>,
}

/// What a build reads: the primitives' boxes and centres, and how it splits.
struct Build<'a> {
    bounds: &'a [Bounds],
    centroids: &'a [Vec3],
    together: usize,
    median_depth: usize,
}

/// From how many primitives a node's two halves are built on two threads:
/// below it a thread's share is too small to pay for the handing over.
const PARALLEL: usize = 1 << 14;

impl Build<'_> {
    /// The binary tree over `order` (which starts at `first` of the whole
    /// order), its root first and each inner node's two children side by
    /// side. Large halves are built in parallel; the tree is the same on
    /// any number of threads.
    fn subtree(&self, order: &mut [u32], first: usize, depth: usize) -> Vec<Node> {
        if order.len() < PARALLEL {
            return self.sequential(order, first, depth);
        }
        let (lo, hi) = order.iter().fold(EMPTY, |b, &i| union(b, self.bounds[i as usize]));
        let Some(middle) = self.split(order, (lo, hi), depth) else {
            return vec![Node { lo, hi, start: first as u32, count: order.len() as u32 }];
        };
        let (left, right) = order.split_at_mut(middle);
        let (left, right) =
            rayon::join(|| self.subtree(left, first, depth + 1), || self.subtree(right, first + middle, depth + 1));
        // [root, left's root, right's root, left's others, right's others]:
        // each part's node k ≥ 1 moves by a fixed amount, and so do the
        // children its inner nodes name (never a part's root)
        let (left_moves, right_moves) = (2, left.len() + 1);
        let moved = |node: &Node, by: usize| match node.count {
            0 => Node { start: node.start + by as u32, ..*node },
            _ => *node,
        };
        let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
        nodes.push(Node { lo, hi, start: 1, count: 0 });
        nodes.push(moved(&left[0], left_moves));
        nodes.push(moved(&right[0], right_moves));
        nodes.extend(left[1..].iter().map(|node| moved(node, left_moves)));
        nodes.extend(right[1..].iter().map(|node| moved(node, right_moves)));
        nodes
    }

    /// `subtree` on one thread.
    fn sequential(&self, order: &mut [u32], first: usize, depth: usize) -> Vec<Node> {
        let mut nodes = Vec::with_capacity(2 * order.len());
        nodes.push(Node { lo: Vec3::ZERO, hi: Vec3::ZERO, start: 0, count: 0 });
        // (node, start, end, depth): ranges of `order` still to place
        let mut todo = vec![(0usize, 0usize, order.len(), depth)];
        while let Some((node, start, end, depth)) = todo.pop() {
            let range = &mut order[start..end];
            let (lo, hi) = range.iter().fold(EMPTY, |b, &i| union(b, self.bounds[i as usize]));
            nodes[node].lo = lo;
            nodes[node].hi = hi;
            let Some(middle) = self.split(range, (lo, hi), depth) else {
                nodes[node].start = (first + start) as u32;
                nodes[node].count = (end - start) as u32;
                continue;
            };
            let left = nodes.len();
            nodes[node].start = left as u32;
            nodes.push(Node { lo, hi, start: 0, count: 0 });
            nodes.push(Node { lo, hi, start: 0, count: 0 });
            todo.push((left, start, start + middle, depth + 1));
            todo.push((left + 1, start + middle, end, depth + 1));
        }
        nodes
    }

    /// Where `range`, whose box is `node`, splits at `depth`: by the
    /// heuristic above `median_depth`, at the median below; `None` for a leaf.
    fn split(&self, range: &mut [u32], node: Bounds, depth: usize) -> Option<usize> {
        match range.len() > LEAF {
            true if depth < self.median_depth => Bvh::split(range, self.bounds, self.centroids, node, self.together),
            true => Some(Bvh::median(range, self.centroids)),
            false => None,
        }
    }
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
    /// Over primitives with boxes `bounds` (index i for `bounds[i]`), which
    /// a leaf tests `together` at a time (the heuristic weighs a leaf by
    /// its tests).
    pub fn new(bounds: &[Bounds], together: usize) -> Self {
        Self::build(bounds, together, MEDIAN_DEPTH)
    }

    /// `new`, halving at the median from `median_depth` down.
    fn build(bounds: &[Bounds], together: usize, median_depth: usize) -> Self {
        if bounds.is_empty() {
            return Bvh::default();
        }
        let centroids: Vec<Vec3> = bounds.iter().map(|(lo, hi)| (*lo + *hi) * 0.5).collect();
        let build = Build { bounds, centroids: &centroids, together: together.max(1), median_depth };
        let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
        let nodes = build.subtree(&mut order, 0, 0);
        Bvh { wide: Self::widen(&nodes), order }
    }

    /// Sorts `range` about the cheapest split by the heuristic and says
    /// where its right part starts; `None` where a leaf is cheaper.
    fn split(range: &mut [u32], bounds: &[Bounds], centroids: &[Vec3], node: Bounds, together: usize) -> Option<usize> {
        // What a leaf of n primitives costs: its tests of `together` at once
        let tests = |n: usize| n.div_ceil(together) as f32;
        let (c_lo, c_hi) = range.iter().fold(EMPTY, |b, &i| union(b, (centroids[i as usize], centroids[i as usize])));
        let extent = c_hi - c_lo;
        let bin_of = |i: u32, axis: usize| {
            let at = (centroids[i as usize][axis] - c_lo[axis]) / extent[axis] * BINS as f32;
            (at as usize).min(BINS - 1)
        };
        // (cost, axis, last bin to the left): the cheapest split on any axis
        let mut best = (f32::INFINITY, 0, 0);
        for axis in (0..3).filter(|&axis| extent[axis] > 0.0) {
            let mut bins = [(EMPTY, 0usize); BINS];
            for &i in range.iter() {
                let bin = &mut bins[bin_of(i, axis)];
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
            for k in 0..BINS - 1 {
                left = (union(left.0, bins[k].0), left.1 + bins[k].1);
                let (right_area, right_count) = right[k + 1];
                let cost = half_area(left.0) * tests(left.1) + right_area * tests(right_count);
                if left.1 > 0 && right_count > 0 && cost < best.0 {
                    best = (cost, axis, k);
                }
            }
        }
        if best.0 == f32::INFINITY {
            // Every centroid in one place: halve by count once too many
            return (range.len() > 2 * LEAF).then_some(range.len() / 2);
        }
        // A leaf costs a test of each primitive; a split, a box test more
        let leaf = half_area(node) * tests(range.len());
        if best.0 >= leaf && range.len() <= 2 * LEAF {
            return None;
        }
        // Partition: bins up to the best's to the left
        let (_, axis, last) = best;
        let mut middle = 0;
        for j in 0..range.len() {
            if bin_of(range[j], axis) <= last {
                range.swap(j, middle);
                middle += 1;
            }
        }
        Some(middle)
    }

    /// Sorts `range` about its median along the axis its centroids spread
    /// most on, and says where its right half starts.
    fn median(range: &mut [u32], centroids: &[Vec3]) -> usize {
        let (lo, hi) = range.iter().fold(EMPTY, |b, &i| union(b, (centroids[i as usize], centroids[i as usize])));
        let axis = (hi - lo).max_position();
        let middle = range.len() / 2;
        range.select_nth_unstable_by(middle, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        middle
    }

    /// The ray as the box tests take it: its origin and the inverse of its
    /// direction in every lane, a zero component's inverse huge but finite
    /// (an infinite one times a zero distance would be NaN).
    #[inline(always)]
    fn lanes_of(ray: &Ray) -> ([Vec4; 3], [Vec4; 3]) {
        let inverse = |d: f32| if d == 0.0 { f32::MAX.copysign(d) } else { 1.0 / d };
        let o = ray.origin;
        let d = ray.direction;
        ([o.x, o.y, o.z].map(Vec4::splat), [inverse(d.x), inverse(d.y), inverse(d.z)].map(Vec4::splat))
    }

    /// Which of `node`'s children the ray meets before `t_max` (a bit a
    /// child), and where it enters each (the exits pushed out by the slab
    /// test's rounding, so no hit in a box is missed).
    #[inline(always)]
    fn enter(node: &Wide, ray: &([Vec4; 3], [Vec4; 3]), t_max: f32) -> (u32, [f32; WIDTH]) {
        let (low, low_near) = Self::enter_half(&node.lo[0], &node.hi[0], ray, t_max);
        let (high, high_near) = Self::enter_half(&node.lo[1], &node.hi[1], ray, t_max);
        let (low_near, high_near) = (low_near.to_array(), high_near.to_array());
        let near = std::array::from_fn(|k| if k < 4 { low_near[k] } else { high_near[k - 4] });
        ((low | high << 4) & node.valid, near)
    }

    /// `enter` for four children's boxes.
    #[inline(always)]
    fn enter_half(
        lo: &[Vec4; 3],
        hi: &[Vec4; 3],
        (origin, inverse): &([Vec4; 3], [Vec4; 3]),
        t_max: f32,
    ) -> (u32, Vec4) {
        // Written out: `map`'s closures may be left out of line
        let (x0, x1) = ((lo[0] - origin[0]) * inverse[0], (hi[0] - origin[0]) * inverse[0]);
        let (y0, y1) = ((lo[1] - origin[1]) * inverse[1], (hi[1] - origin[1]) * inverse[1]);
        let (z0, z1) = ((lo[2] - origin[2]) * inverse[2], (hi[2] - origin[2]) * inverse[2]);
        let near = x0.min(x1).max(y0.min(y1)).max(z0.min(z1)).max(Vec4::ZERO);
        let far = x0.max(x1).min(y0.max(y1)).min(z0.max(z1)) * (1.0 + 2.0 * gamma(3));
        let met = near.cmple(far) & near.cmplt(Vec4::splat(t_max));
        (met.bitmask(), near)
    }

    /// The nearest hit within (0, t_max) of `test` (given a primitive and
    /// the nearest hit so far, its hit nearer than that, with its t), and
    /// the primitive's index. Children are visited nearest first, and none
    /// the ray enters beyond the nearest hit so far.
    #[inline]
    pub fn nearest<H>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<(f32, H)>,
    ) -> Option<(u32, H)> {
        self.nearest_leaf(
            ray,
            t_max,
            |_, _| {},
            |start, count, mut best_t| {
                let mut found = None;
                for &i in &self.order[start as usize..(start + count) as usize] {
                    if let Some((t, hit)) = test(i, best_t) {
                        best_t = t;
                        found = Some((t, (i, hit)));
                    }
                }
                found
            },
        )
    }

    /// Whether `test` (given a primitive) holds for any primitive whose box
    /// the ray meets within (0, t_max).
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32, mut test: impl FnMut(u32) -> bool) -> bool {
        self.any_leaf(ray, t_max, |start, count| {
            self.order[start as usize..(start + count) as usize].iter().any(|&i| test(i))
        })
    }

    /// As `nearest`, a leaf at a time: `test` is given a leaf's (start,
    /// count) (its run of `order`, or what `map_leaves` made of it) and the
    /// nearest hit so far, and answers with the leaf's nearer hit;
    /// `prefetch_leaf` may ask the memory for a leaf the ray will test.
    #[inline]
    pub fn nearest_leaf<H>(
        &self,
        ray: &Ray,
        t_max: f32,
        prefetch_leaf: impl Fn(u32, u32),
        mut test: impl FnMut(u32, u32, f32) -> Option<(f32, H)>,
    ) -> Option<H> {
        if self.wide.is_empty() {
            return None;
        }
        let lanes = Self::lanes_of(ray);
        let mut best_t = t_max;
        let mut found = None;
        // (start, count, entry): a wide node (count 0) or a leaf
        let mut stack = [(0u32, 0u32, 0.0f32); STACK];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let (start, count, entry) = stack[depth];
            if entry >= best_t {
                continue;
            }
            if count > 0 {
                if let Some((t, hit)) = test(start, count, best_t) {
                    best_t = t;
                    found = Some(hit);
                }
                continue;
            }
            let node = &self.wide[start as usize];
            let (mut met, near) = Self::enter(node, &lanes, best_t);
            self.prefetch(node, met, &prefetch_leaf);
            // Farthest first onto the stack, so the nearest comes off first
            let first = depth;
            while met != 0 {
                let k = met.trailing_zeros() as usize;
                met &= met - 1;
                let mut at = depth;
                while at > first && stack[at - 1].2 < near[k] {
                    stack[at] = stack[at - 1];
                    at -= 1;
                }
                stack[at] = (node.start[k], node.count[k] as u32, near[k]);
                depth += 1;
            }
        }
        found
    }

    /// Asks the memory for `node`'s children `met`, all at once: the
    /// inner nodes here, the leaves through `prefetch_leaf` (given a leaf's
    /// start and count). A ray that goes on to more than one of them finds
    /// the later ones waiting, where it would wait for each in turn.
    #[inline(always)]
    fn prefetch(&self, node: &Wide, mut met: u32, prefetch_leaf: &impl Fn(u32, u32)) {
        while met != 0 {
            let k = met.trailing_zeros() as usize;
            met &= met - 1;
            match node.count[k] {
                0 => prefetch_lines(&self.wide[node.start[k] as usize], 4),
                count => prefetch_leaf(node.start[k], count as u32),
            }
        }
    }

    /// As `any_hit`, a leaf at a time (as `nearest_leaf` gives them).
    #[inline]
    pub fn any_leaf(&self, ray: &Ray, t_max: f32, mut test: impl FnMut(u32, u32) -> bool) -> bool {
        if self.wide.is_empty() {
            return false;
        }
        let lanes = Self::lanes_of(ray);
        let mut stack = [(0u32, 0u32); STACK];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let (start, count) = stack[depth];
            if count > 0 {
                if test(start, count) {
                    return true;
                }
                continue;
            }
            let node = &self.wide[start as usize];
            let (mut met, _) = Self::enter(node, &lanes, t_max);
            while met != 0 {
                let k = met.trailing_zeros() as usize;
                met &= met - 1;
                stack[depth] = (node.start[k], node.count[k] as u32);
                depth += 1;
            }
        }
        false
    }

    /// Each leaf's primitives, in the order `map_leaves` meets them.
    pub fn leaves(&self) -> Vec<&[u32]> {
        let children = self.wide.iter().flat_map(|node| (0..WIDTH).map(move |k| (node, k)));
        (children.filter(|(node, k)| node.valid & (1 << k) != 0 && node.count[*k] != 0))
            .map(|(node, k)| &self.order[node.start[k] as usize..][..node.count[k] as usize])
            .collect()
    }

    /// Renames every leaf: `rename` is given a leaf's primitives and
    /// answers with the (start, count) the leaf tests will be given in
    /// their place, the count no more than the primitives; a count of zero
    /// removes the leaf (nothing in it can be hit).
    pub fn map_leaves(&mut self, mut rename: impl FnMut(&[u32]) -> (u32, u32)) {
        for node in &mut self.wide {
            for k in 0..WIDTH {
                if node.valid & (1 << k) == 0 || node.count[k] == 0 {
                    continue;
                }
                let (start, count) = (node.start[k] as usize, node.count[k] as usize);
                let (renamed, count) = rename(&self.order[start..start + count]);
                // No more than the leaf's primitives, so it fits
                (node.start[k], node.count[k]) = (renamed, count.min(2 * LEAF as u32) as u8);
                if node.count[k] == 0 {
                    node.valid &= !(1 << k);
                }
            }
        }
    }

    /// The binary tree `nodes` as eight-wide nodes: each takes its node's
    /// children, then opens the largest of those that are inner nodes until
    /// it holds eight.
    fn widen(nodes: &[Node]) -> Vec<Wide> {
        let mut wide = vec![Wide::EMPTY];
        let mut todo = vec![(0usize, 0usize)];
        while let Some((binary, at)) = todo.pop() {
            let node = &nodes[binary];
            let mut children = match node.count {
                0 => vec![node.start as usize, node.start as usize + 1],
                _ => vec![binary],
            };
            while children.len() < WIDTH {
                let area = |&(_, &n): &(usize, &usize)| half_area((nodes[n].lo, nodes[n].hi));
                let inner = children.iter().enumerate().filter(|(_, &n)| nodes[n].count == 0);
                let Some((k, _)) = inner.max_by(|a, b| area(a).total_cmp(&area(b))) else { break };
                let opened = children.swap_remove(k);
                children.extend([nodes[opened].start as usize, nodes[opened].start as usize + 1]);
            }
            let mut filled = Wide::EMPTY;
            for (k, &n) in children.iter().enumerate() {
                let child = &nodes[n];
                for axis in 0..3 {
                    filled.lo[k / 4][axis][k % 4] = child.lo[axis];
                    filled.hi[k / 4][axis][k % 4] = child.hi[axis];
                }
                filled.valid |= 1 << k;
                (filled.start[k], filled.count[k]) = match child.count {
                    0 => {
                        todo.push((n, wide.len()));
                        wide.push(Wide::EMPTY);
                        (wide.len() as u32 - 1, 0)
                    }
                    count => (child.start, count as u8),
                };
            }
            wide[at] = filled;
        }
        wide
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
            let bvh = Bvh::new(&bounds_of(&list), 1 + count % 4);
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
        let bvh = Bvh::new(&bounds_of(&list), 4);
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
        assert!(bvh.wide.len() < list.len());
    }

    /// Past its median depth the build halves what is left: every leaf
    /// holds at most `2 * LEAF` primitives (`LEAF` once only halves made
    /// it), each primitive is in one, and the tree is no deeper than the
    /// median depth and the halvings (`MAX_DEPTH`'s bound).
    #[test]
    fn past_the_median_depth_the_build_halves() {
        let mut s = Sampler::new(0, 0, 59);
        let list = triangles(&mut s, 1000);
        for median_depth in [0, 3, MEDIAN_DEPTH] {
            let mut bvh = Bvh::build(&bounds_of(&list), 1, median_depth);
            let mut seen = Vec::new();
            let most = if median_depth == 0 { LEAF } else { 2 * LEAF };
            bvh.map_leaves(|ids| {
                assert!(ids.len() <= most, "a leaf of {} past depth {median_depth}", ids.len());
                seen.extend_from_slice(ids);
                (0, ids.len() as u32)
            });
            seen.sort_unstable();
            assert_eq!(seen, (0..list.len() as u32).collect::<Vec<_>>());
            // Halvings of 1000 down to at most four: 8
            assert!(depth(&bvh, 0) <= median_depth + 8, "depth {} past {median_depth}", depth(&bvh, 0));
        }
    }

    /// Halves built on two threads make the tree one thread makes, node
    /// for node, whatever the threads' timing.
    #[test]
    fn the_parallel_build_makes_the_tree_one_thread_makes() {
        let mut s = Sampler::new(0, 0, 61);
        let list = triangles(&mut s, 3 * PARALLEL);
        let bounds = bounds_of(&list);
        let centroids: Vec<Vec3> = bounds.iter().map(|(lo, hi)| (*lo + *hi) * 0.5).collect();
        let build = Build { bounds: &bounds, centroids: &centroids, together: 4, median_depth: MEDIAN_DEPTH };
        let mut parallel_order: Vec<u32> = (0..bounds.len() as u32).collect();
        let mut sequential_order = parallel_order.clone();
        let parallel = build.subtree(&mut parallel_order, 0, 0);
        let sequential = build.sequential(&mut sequential_order, 0, 0);
        assert_eq!(parallel_order, sequential_order);
        assert!(Bvh::widen(&parallel) == Bvh::widen(&sequential), "the eight-wide trees differ");
        assert_eq!(parallel.len(), sequential.len());
    }

    /// Levels of eight-wide nodes below `node` (at most the binary tree's).
    fn depth(bvh: &Bvh, node: usize) -> usize {
        let wide = &bvh.wide[node];
        let inner = (0..WIDTH).filter(|&k| wide.valid & (1 << k) != 0 && wide.count[k] == 0);
        1 + inner.map(|k| depth(bvh, wide.start[k] as usize)).max().unwrap_or(0)
    }

    /// A node is four cache lines, and starts one.
    #[test]
    fn a_node_is_four_cache_lines() {
        assert_eq!((std::mem::size_of::<Wide>(), std::mem::align_of::<Wide>()), (256, 64));
    }
}
