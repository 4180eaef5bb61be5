//! Records made out of turn, put back in the order of the work items that
//! made them: eight lanes finish photons and light subpaths as they end,
//! not in index order, and a map or a film must not depend on how the
//! lanes fell.

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

/// `records`, record i made by item `places[i]` of `0..items`, in item
/// order, each item's in the order they were made; and where each item's
/// records end.
pub fn by_item<T: Copy>(records: &[T], places: &[u32], items: usize) -> (Vec<T>, Vec<u32>) {
    debug_assert_eq!(records.len(), places.len());
    let (starts, order) = by_key(places, items);
    (order.iter().map(|&i| records[i as usize]).collect(), starts[1..].to_vec())
}

/// A stable counting sort of `keys.len()` items by their keys in
/// `0..key_count`: `order` lists the items by key, each key's in their own
/// order, and key k's are `order[starts[k]..starts[k + 1]]`. Large sorts
/// run on up to `BLOCKS` threads, each counting and placing its own block
/// of the items: the same result, which no thread count changes (SPPM
/// sorts millions of photons a pass).
pub fn by_key(keys: &[u32], key_count: usize) -> (Vec<u32>, Vec<u32>) {
    let blocks = rayon::current_num_threads().min(BLOCKS).min(keys.len() / PARALLEL_FROM);
    if blocks < 2 {
        return by_key_serial(keys, key_count);
    }
    let block_len = keys.len().div_ceil(blocks);
    // Each block's count of each key, then where its first item of that key goes
    let mut places: Vec<Vec<u32>> = keys
        .par_chunks(block_len)
        .map(|block| {
            let mut counts = vec![0u32; key_count];
            for &key in block {
                counts[key as usize] += 1;
            }
            counts
        })
        .collect();
    let mut starts = vec![0u32; key_count + 1];
    // Keys in spans, each span's items counted, then placed from its start
    let span = key_count.div_ceil(SPANS).max(1);
    let totals: Vec<u32> = (0..key_count.div_ceil(span))
        .into_par_iter()
        .map(|s| {
            let range = s * span..((s + 1) * span).min(key_count);
            places.iter().map(|counts| counts[range.clone()].iter().sum::<u32>()).sum()
        })
        .collect();
    let mut spans: Vec<Span> = Vec::with_capacity(totals.len());
    let mut first = 0;
    for (s, starts) in starts[..key_count].chunks_mut(span).enumerate() {
        spans.push(Span { first, starts, counts: Vec::with_capacity(blocks) });
        first += totals[s];
    }
    for counts in &mut places {
        for (s, part) in counts.chunks_mut(span).enumerate() {
            spans[s].counts.push(part);
        }
    }
    spans.into_par_iter().for_each(|Span { first: mut next, starts, mut counts }| {
        for (k, start) in starts.iter_mut().enumerate() {
            *start = next;
            for block in counts.iter_mut() {
                let count = block[k];
                block[k] = next;
                next += count;
            }
        }
    });
    starts[key_count] = keys.len() as u32;
    // Each block's items to their places: apart from every other block's
    let order: Vec<AtomicU32> = (0..keys.len()).map(|_| AtomicU32::new(0)).collect();
    keys.par_chunks(block_len).zip(places.par_iter_mut()).enumerate().for_each(|(b, (block, next))| {
        for (i, &key) in block.iter().enumerate() {
            order[next[key as usize] as usize].store((b * block_len + i) as u32, Ordering::Relaxed);
            next[key as usize] += 1;
        }
    });
    (starts, order.into_iter().map(AtomicU32::into_inner).collect())
}

/// A span of keys in `by_key`: where its first item goes, its keys'
/// starts, and each block's counts of its keys (to become where the
/// block's first item of each goes).
struct Span<'a> {
    first: u32,
    starts: &'a mut [u32],
    counts: Vec<&'a mut [u32]>,
}

/// `by_key` on the calling thread.
fn by_key_serial(keys: &[u32], key_count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut starts = vec![0u32; key_count + 1];
    for &key in keys {
        starts[key as usize + 1] += 1;
    }
    for i in 1..starts.len() {
        starts[i] += starts[i - 1];
    }
    let mut next = starts[..key_count].to_vec();
    let mut order = vec![0u32; keys.len()];
    for (item, &key) in keys.iter().enumerate() {
        order[next[key as usize] as usize] = item as u32;
        next[key as usize] += 1;
    }
    (starts, order)
}

/// At most this many blocks sort at once: each holds a count of every key.
const BLOCKS: usize = 4;
/// Items a block has at least: fewer sort on one thread.
const PARALLEL_FROM: usize = 1 << 16;
/// The spans of keys whose places are worked out at once.
const SPANS: usize = 64;

/// How many records ahead a gather in another order than memory's asks
/// for (`prefetch`): enough to cover a miss, few enough to stay cached.
pub const PREFETCH_AHEAD: usize = 16;

/// A hint to bring `value`'s cache line in; nothing else. A gather in an
/// order of its own misses the cache at every record, and the CPU cannot
/// guess the next address.
#[inline(always)]
#[allow(unsafe_code)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching reads nothing and cannot fault; the pointer is a reference's
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((value as *const T).cast::<i8>())
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    #[test]
    fn records_come_out_in_item_order_each_items_in_the_order_made() {
        // Item 2's three records, interleaved with items 0 and 1's; item 3 made none
        let places = [2, 0, 2, 1, 2, 0];
        let records = ['a', 'b', 'c', 'd', 'e', 'f'];
        let (sorted, ends) = by_item(&records, &places, 4);
        assert_eq!(sorted, ['b', 'f', 'd', 'a', 'c', 'e']);
        assert_eq!(ends, [2, 3, 6, 6]);
        assert_eq!(by_item::<char>(&[], &[], 3), (vec![], vec![0, 0, 0]));
        assert_eq!(by_key(&places, 4), (vec![0, 2, 3, 6, 6], vec![1, 5, 3, 0, 2, 4]));
    }

    /// Sorts large enough to run in blocks, on two to five threads (more
    /// than `BLOCKS`), give what one thread gives, which is the stable
    /// sort: no image depends on the thread count.
    #[test]
    fn sorts_in_blocks_on_any_thread_count_give_the_stable_sort() {
        let mut s = Sampler::new(3, 1, 4);
        for (count, key_count) in
            [(2 * PARALLEL_FROM + 17, 1000), (3 * PARALLEL_FROM + 1, 1 << 20), (4 * PARALLEL_FROM, 3)]
        {
            let keys: Vec<u32> = (0..count).map(|_| (s.next_u64() % key_count as u64) as u32).collect();
            let (starts, order) = by_key_serial(&keys, key_count);
            let sorted = |w: &[u32]| (keys[w[0] as usize], w[0]) < (keys[w[1] as usize], w[1]);
            assert!(order.windows(2).all(sorted), "stable by key");
            assert!((0..key_count).all(|k| order[starts[k] as usize..starts[k + 1] as usize]
                .iter()
                .all(|&i| keys[i as usize] == k as u32)));
            for threads in 2..=5 {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
                let blocks = pool.install(|| by_key(&keys, key_count));
                assert!(blocks == (starts.clone(), order.clone()), "{count} keys of {key_count}, {threads} threads");
            }
        }
    }
}
