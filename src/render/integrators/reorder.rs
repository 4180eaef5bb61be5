//! Records made out of turn, put back in the order of the work items that
//! made them: eight lanes finish photons and light subpaths as they end,
//! not in index order, and a map or a film must not depend on how the
//! lanes fell.

/// `records`, record i made by item `places[i]` of `0..items`, in item
/// order, each item's in the order they were made (a stable counting
/// sort); and where each item's records end.
pub fn by_item<T: Copy>(records: &[T], places: &[u32], items: usize) -> (Vec<T>, Vec<u32>) {
    debug_assert_eq!(records.len(), places.len());
    let mut first = vec![0u32; items + 1];
    for &place in places {
        first[place as usize + 1] += 1;
    }
    for i in 1..first.len() {
        first[i] += first[i - 1];
    }
    let ends = first[1..].to_vec();
    let Some(&any) = records.first() else { return (Vec::new(), ends) };
    let mut sorted = vec![any; records.len()];
    for (record, &place) in records.iter().zip(places) {
        let at = &mut first[place as usize];
        sorted[*at as usize] = *record;
        *at += 1;
    }
    (sorted, ends)
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
    }
}
