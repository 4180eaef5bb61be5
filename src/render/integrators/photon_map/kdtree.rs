//! The photon map's kd-tree (Bentley 1975, as Jensen uses it): photons in
//! one flat array in left-balanced heap order — children of node i at 2i+1
//! and 2i+2, no pointers — split on the axis of largest extent, built by
//! linear-time median selection, queried for the k nearest with a bounded
//! max-heap on squared distances. Queries within a radius (SPPM's gathers,
//! VCM's merges) go to the hash grid, `cells`.

use glam::Vec3;

use crate::render::integrators::photon_map::record::Photon;
use crate::render::integrators::reorder::{prefetch, PREFETCH_AHEAD};

/// The photon map.
#[derive(Debug)]
pub struct PhotonKdTree {
    photons: Vec<Photon>,
    depth: usize,
}

/// Nodes in the left subtree of a left-balanced tree of `n` nodes: the last
/// level fills from the left, so the left subtree is complete first.
fn left_subtree_size(n: usize) -> usize {
    if n <= 1 {
        return 0;
    }
    let levels = usize::BITS - 1 - n.leading_zeros(); // full levels below the last
    let full = (1usize << levels) - 1;
    let last = n - full;
    let half_last = 1usize << (levels - 1);
    (full - 1) / 2 + last.min(half_last)
}

/// Levels of a left-balanced tree of `n` nodes.
fn depth_of(n: usize) -> usize {
    (usize::BITS - n.leading_zeros()) as usize
}

/// Segments at least this long split their halves between threads.
const PARALLEL_SEGMENT: usize = 1 << 16;

/// What the partition moves, sixteen bytes however large a record is: a
/// record's position as integers that order as `f32::total_cmp` orders
/// the floats (`ordered`), and its index among the records. A step of the
/// selection is then one integer comparison, where `total_cmp` took two
/// conversions, and a segment's bounds are four-lane integer minima.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Key {
    /// x, y, z through `ordered`, then the record's index.
    lanes: [i32; 4],
}

/// `x`'s bits as an integer that orders as `f32::total_cmp` orders floats
/// (the same transform it makes); its own inverse.
fn ordered(x: i32) -> i32 {
    x ^ (((x >> 31) as u32) >> 1) as i32
}

impl Key {
    fn new(position: Vec3, record: u32) -> Self {
        let [x, y, z] = position.to_array().map(|c| ordered(c.to_bits() as i32));
        Self { lanes: [x, y, z, record as i32] }
    }

    fn record(self) -> usize {
        self.lanes[3] as u32 as usize
    }
}

/// The axis of the keys' largest extent, as `Vec3::max_position` picks it
/// from the extents in floats (which the integer bounds give exactly, the
/// positions being finite).
fn widest_axis(keys: &[Key]) -> usize {
    let (mut lo, mut hi) = ([i32::MAX; 4], [i32::MIN; 4]);
    for key in keys {
        // All four lanes, so that the loop runs as vector minima; the
        // record's lane is not read
        for c in 0..4 {
            lo[c] = lo[c].min(key.lanes[c]);
            hi[c] = hi[c].max(key.lanes[c]);
        }
    }
    let float = |o: i32| f32::from_bits(ordered(o) as u32);
    (Vec3::new(float(hi[0]), float(hi[1]), float(hi[2])) - Vec3::new(float(lo[0]), float(lo[1]), float(lo[2])))
        .max_position()
}

/// Partition `keys` into a left-balanced tree's in-order: the median of the
/// segment (the root's place, `left_subtree_size`) on the axis of the
/// segment's largest extent, which `axes` records at the median's place,
/// then each side alike.
fn partition(keys: &mut [Key], axes: &mut [u8]) {
    let length = keys.len();
    if length <= 1 {
        // A leaf (half the nodes): its extent is nothing, on any axis
        if let Some(leaf) = axes.first_mut() {
            *leaf = Vec3::ZERO.max_position() as u8;
        }
        return;
    }
    let axis = widest_axis(keys);
    let median = left_subtree_size(length);
    // One comparison per axis, each compiled on its own (indexing by a
    // variable axis inside the comparison cost a third of the build)
    match axis {
        0 => keys.select_nth_unstable_by_key(median, |k| k.lanes[0]),
        1 => keys.select_nth_unstable_by_key(median, |k| k.lanes[1]),
        _ => keys.select_nth_unstable_by_key(median, |k| k.lanes[2]),
    };
    axes[median] = axis as u8;
    let (left, right) = keys.split_at_mut(median);
    let (left_axes, right_axes) = axes.split_at_mut(median);
    let (right, right_axes) = (&mut right[1..], &mut right_axes[1..]);
    if length >= PARALLEL_SEGMENT {
        rayon::join(|| partition(left, left_axes), || partition(right, right_axes));
    } else {
        partition(left, left_axes);
        partition(right, right_axes);
    }
}

/// The records in the order `keys` put them (the tree's in-order), with
/// their axes, into heap order: an in-order walk of the heap's indices
/// meets the nodes in that order, so it takes the keys in sequence (a stack
/// of the left spine, no subtree sizes).
fn to_heap_order(records: &[Photon], keys: &[Key], axes: &[u8]) -> Vec<Photon> {
    let n = keys.len();
    let mut tree = vec![Photon::default(); n];
    // A node's depth is below 64 for any n that fits in memory
    let mut stack = [0usize; 64];
    let (mut top, mut node, mut next) = (0, 0, 0);
    loop {
        while node < n {
            stack[top] = node;
            top += 1;
            node = 2 * node + 1;
        }
        if top == 0 {
            return tree;
        }
        top -= 1;
        // The reads go wherever the keys say: ask for one some way ahead
        if let Some(ahead) = keys.get(next + PREFETCH_AHEAD) {
            prefetch(&records[ahead.record()]);
        }
        let mut record = records[keys[next].record()];
        record.set_axis(axes[next] as usize);
        tree[stack[top]] = record;
        next += 1;
        node = 2 * stack[top] + 2;
    }
}

impl PhotonKdTree {
    /// Balance `photons` into a left-balanced tree in O(n log n): each
    /// segment of their keys (position and index, whatever a record's size)
    /// is partitioned in place about its median on the axis of its points'
    /// largest extent, the two halves of a large segment in parallel; every
    /// segment's median then sits at its split, so the keys end in the
    /// tree's in-order, and one in-order walk writes the records they name
    /// in heap order. The tree is the same on any number of threads.
    pub fn build(photons: Vec<Photon>) -> Self {
        let n = photons.len();
        // Indices fit in u32, as the queries' stacks assume: the limits keep
        // every tree far smaller
        let mut keys: Vec<Key> = photons.iter().enumerate().map(|(i, p)| Key::new(p.position, i as u32)).collect();
        let mut axes = vec![0u8; n];
        partition(&mut keys, &mut axes);
        Self { photons: to_heap_order(&photons, &keys, &axes), depth: depth_of(n) }
    }

    /// A tree read back from a file, already in heap order; refused (with
    /// the first photon out of place) unless every split holds, since the
    /// queries prune by them: each photon lies inside the box its ancestors'
    /// splits leave it (left of a split ≤, right ≥, on that split's axis).
    pub fn from_heap_order(photons: Vec<Photon>) -> Result<Self, usize> {
        let n = photons.len();
        // (node, lower and upper bounds from its ancestors): O(n) in all
        let mut stack = Vec::with_capacity(128);
        if n > 0 {
            stack.push((0usize, Vec3::NEG_INFINITY, Vec3::INFINITY));
        }
        while let Some((node, lo, hi)) = stack.pop() {
            let p = photons[node].position;
            if !(p.cmpge(lo).all() && p.cmple(hi).all()) {
                return Err(node);
            }
            let axis = photons[node].axis();
            let (mut left_hi, mut right_lo) = (hi, lo);
            left_hi[axis] = p[axis];
            right_lo[axis] = p[axis];
            for (child, lo, hi) in [(2 * node + 1, lo, left_hi), (2 * node + 2, right_lo, hi)] {
                if child < n {
                    stack.push((child, lo, hi));
                }
            }
        }
        Ok(Self { photons, depth: depth_of(n) })
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Heap-ordered photons; `Neighbours` indices point here.
    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.photons.as_slice())
    }

    /// The `k` nearest photons to `position` within `max_radius` (inclusive)
    /// into `out`; with a `normal`, only photons arriving at its front side.
    /// Returns the number of nodes visited.
    pub fn k_nearest(
        &self,
        position: Vec3,
        normal: Option<Vec3>,
        k: usize,
        max_radius: f32,
        out: &mut Neighbours,
    ) -> usize {
        out.reset(k);
        let n = self.photons.len();
        if k == 0 || n == 0 || max_radius.is_nan() || max_radius < 0.0 {
            return 0;
        }
        let photons = &self.photons[..];
        let mut bound = max_radius * max_radius;
        let mut visited = 0;
        let mut stack = [(0u32, 0f32); 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (start, plane_distance2) = stack[top];
            // The bound may have shrunk since this subtree was deferred
            if plane_distance2 > bound {
                continue;
            }
            let mut node = start as usize;
            loop {
                visited += 1;
                // Ask now for the eight great-grandchildren (8i+7..8i+14, side
                // by side: four prefetches over their 224 bytes), which the
                // walk reaches three loads later. Each level below the cached
                // top would be a miss in turn, above all for a final gather's
                // queries, which land anywhere.
                for great_grandchild in [7, 9, 11, 14] {
                    if let Some(photon) = photons.get(8 * node + great_grandchild) {
                        prefetch(photon);
                    }
                }
                let photon = &photons[node];
                let offset = position - photon.position;
                let distance2 = offset.length_squared();
                if distance2 <= bound && normal.is_none_or(|n| photon.incoming_direction().dot(n) < 0.0) {
                    out.push(distance2, node as u32);
                    if out.is_full() {
                        bound = out.max_dist2();
                    }
                }
                let delta = offset[photon.axis()];
                let (near, far) = if delta < 0.0 { (2 * node + 1, 2 * node + 2) } else { (2 * node + 2, 2 * node + 1) };
                if far < n && delta * delta <= bound {
                    stack[top] = (far as u32, delta * delta);
                    top += 1;
                }
                if near >= n {
                    break;
                }
                node = near;
            }
        }
        visited
    }
}

/// A reusable bounded max-heap of (squared distance, photon index): the
/// farthest of the k best is at the root, ready to be replaced.
#[derive(Clone, Debug, Default)]
pub struct Neighbours {
    heap: Vec<(f32, u32)>,
    k: usize,
}

impl Neighbours {
    pub fn new(k: usize) -> Self {
        Self { heap: Vec::with_capacity(k), k }
    }

    fn reset(&mut self, k: usize) {
        self.heap.clear();
        self.k = k;
    }

    pub fn len(&self) -> usize {
        self.heap.len()
    }

    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    #[inline]
    fn is_full(&self) -> bool {
        self.heap.len() >= self.k
    }

    /// Squared distance of the farthest kept photon (0 when empty).
    #[inline]
    pub fn max_dist2(&self) -> f32 {
        self.heap.first().map_or(0.0, |e| e.0)
    }

    pub fn as_slice(&self) -> &[(f32, u32)] {
        &self.heap
    }

    #[inline]
    fn push(&mut self, distance2: f32, index: u32) {
        let heap = &mut self.heap;
        if heap.len() < self.k {
            // Sift up
            heap.push((distance2, index));
            let mut i = heap.len() - 1;
            while i > 0 {
                let parent = (i - 1) / 2;
                if heap[parent].0 >= heap[i].0 {
                    break;
                }
                heap.swap(parent, i);
                i = parent;
            }
        } else if distance2 < heap[0].0 {
            // Replace the farthest, sift down
            let len = heap.len();
            let mut i = 0;
            loop {
                let left = 2 * i + 1;
                if left >= len {
                    break;
                }
                let right = left + 1;
                let child = if right < len && heap[right].0 > heap[left].0 { right } else { left };
                if heap[child].0 <= distance2 {
                    break;
                }
                heap[i] = heap[child];
                i = child;
            }
            heap[i] = (distance2, index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    fn random_photons(n: usize, seed: u64) -> Vec<Photon> {
        let mut s = Sampler::new(0, 0, seed);
        (0..n)
            .map(|_| {
                let p = Vec3::new(s.next_f32() * 4.0, s.next_f32(), s.next_f32() * 2.0);
                Photon::new(p, -Vec3::Y, [1.0; 3])
            })
            .collect()
    }

    /// Heap order and split planes: every photon in node i's left subtree is
    /// ≤ node i on its axis, every one in its right subtree ≥, and the axis
    /// is the subtree's largest extent.
    #[test]
    fn split_planes_and_axes_hold_for_every_node() {
        for n in [1, 2, 3, 7, 8, 100, 1000, 1023, 1024] {
            let tree = PhotonKdTree::build(random_photons(n, n as u64));
            let photons = tree.photons();
            assert_eq!(photons.len(), n);
            assert_eq!(tree.depth(), (n as f64 + 1.0).log2().ceil() as usize);
            fn subtree(i: usize, n: usize, out: &mut Vec<usize>) {
                if i < n {
                    out.push(i);
                    subtree(2 * i + 1, n, out);
                    subtree(2 * i + 2, n, out);
                }
            }
            for i in 0..n {
                let axis = photons[i].axis();
                let v = photons[i].position[axis];
                let (mut left, mut right, mut all) = (Vec::new(), Vec::new(), Vec::new());
                subtree(2 * i + 1, n, &mut left);
                subtree(2 * i + 2, n, &mut right);
                subtree(i, n, &mut all);
                assert!(left.iter().all(|&j| photons[j].position[axis] <= v));
                assert!(right.iter().all(|&j| photons[j].position[axis] >= v));
                let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
                for &j in &all {
                    lo = lo.min(photons[j].position);
                    hi = hi.max(photons[j].position);
                }
                let extent = hi - lo;
                assert_eq!(extent[axis], extent.max_element(), "node {i} of {n}");
            }
        }
    }

    #[test]
    fn a_built_tree_reads_back_and_a_photon_out_of_place_is_found() {
        let tree = PhotonKdTree::build(random_photons(500, 9));
        let photons = tree.photons().to_vec();
        assert_eq!(PhotonKdTree::from_heap_order(photons.clone()).unwrap().photons(), tree.photons());
        // Node 3 is in node 0's left subtree: beyond node 0's split it breaks the order
        let mut moved = photons.clone();
        let axis = moved[0].axis();
        moved[3].position[axis] = moved[0].position[axis] + 1.0;
        assert_eq!(PhotonKdTree::from_heap_order(moved).unwrap_err(), 3);
        let mut swapped = photons;
        swapped.swap(1, 2);
        assert!(PhotonKdTree::from_heap_order(swapped).is_err());
    }

    /// Large enough that its top segments split between threads: the same
    /// tree on one thread as on two, every split holding, no photon lost.
    #[test]
    fn a_tree_built_in_parallel_is_the_one_built_on_one_thread() {
        let photons = random_photons(3 * PARALLEL_SEGMENT + 17, 4);
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| PhotonKdTree::build(photons.clone()))
        };
        let (one, two) = (on(1), on(2));
        let bits =
            |p: &Photon| [p.position.x.to_bits(), p.position.y.to_bits(), p.position.z.to_bits(), p.axis() as u32];
        assert!(one.photons().iter().map(bits).eq(two.photons().iter().map(bits)), "the trees differ");
        assert!(PhotonKdTree::from_heap_order(two.photons().to_vec()).is_ok());
        let sorted_positions = |photons: &[Photon]| {
            let mut v: Vec<[u32; 3]> = photons.iter().map(|p| p.position.to_array().map(f32::to_bits)).collect();
            v.sort_unstable();
            v
        };
        assert!(sorted_positions(two.photons()) == sorted_positions(&photons), "photons lost or repeated");
    }

    #[test]
    fn left_subtree_sizes() {
        assert_eq!([1, 2, 3, 4, 5, 6, 7, 8].map(left_subtree_size), [0, 1, 1, 2, 3, 3, 3, 4]);
    }
}
