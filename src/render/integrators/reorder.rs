//! Records made out of turn, put back in the order of the work items that
//! made them: eight lanes finish photons and light subpaths as they end,
//! not in index order, and a map or a film must not depend on how the
//! lanes fell.

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
/// order, and key k's are `order[starts[k]..starts[k + 1]]`.
pub fn by_key(keys: &[u32], key_count: usize) -> (Vec<u32>, Vec<u32>) {
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
}
