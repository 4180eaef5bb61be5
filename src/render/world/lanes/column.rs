//! A closed set's values read by eight lane indices at once: each sphere's
//! radius, each surface's albedo, one `Column` per field.
//!
//! Read lane by lane, a field cost eight loads, each behind its lane's
//! bounds check, and seven inserts into the register; a set of up to
//! sixteen members (every preset's spheres and surfaces) is read by two
//! permutes of registers instead, a larger one by a hardware gather.

use glam::Vec3;

use super::{Index8, F8, LANES, V8};

/// One value per member; at least sixteen, the rest zeros.
#[derive(Clone, Debug, Default)]
pub struct Column(Vec<f32>);

/// Members read by `F8::permuted` (a larger column is gathered).
const PERMUTED: usize = 2 * LANES;

impl Column {
    pub fn new(values: impl IntoIterator<Item = f32>) -> Self {
        let mut values: Vec<f32> = values.into_iter().collect();
        values.resize(values.len().max(PERMUTED), 0.0);
        Column(values)
    }

    /// Lane i holds member `index[i]`'s value (a member beyond the set
    /// reads a zero or another member's value, never outside the column).
    #[inline(always)]
    pub fn get(&self, index: Index8) -> F8 {
        match <&[f32; PERMUTED]>::try_from(self.0.as_slice()) {
            Ok(table) => {
                let (low, high) = table.split_at(LANES);
                F8::permuted(F8::load(eight(low)), F8::load(eight(high)), index)
            }
            Err(_) => F8::gathered(&self.0, index),
        }
    }
}

#[inline(always)]
fn eight(values: &[f32]) -> &[f32; LANES] {
    values.try_into().expect("a permuted column holds two eights")
}

/// A vector field: a column per axis.
#[derive(Clone, Debug, Default)]
pub struct Column3([Column; 3]);

impl Column3 {
    pub fn new(values: impl IntoIterator<Item = Vec3> + Clone) -> Self {
        let axis = |a: usize| Column::new(values.clone().into_iter().map(move |v| v[a]));
        Column3([axis(0), axis(1), axis(2)])
    }

    #[inline(always)]
    pub fn get(&self, index: Index8) -> V8 {
        let [x, y, z] = &self.0;
        V8 { x: x.get(index), y: y.get(index), z: z.get(index) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::lanes::supported;

    /// Every size either way of the permutes' sixteen: each lane reads its
    /// member, in every order, and indices past the set stay in the column.
    #[test]
    fn lanes_read_the_members_their_indices_name() {
        assert!(supported(), "the lanes need AVX2");
        for size in [1, 7, 8, 9, 15, 16, 17, 40] {
            let values: Vec<f32> = (0..size).map(|k| 1.5 + k as f32 * 0.25).collect();
            let column = Column::new(values.iter().copied());
            for start in 0..size {
                let index: [i32; LANES] = std::array::from_fn(|i| ((start + i * 5) % size) as i32);
                let read = column.get(F8::from_fn(|i| index[i] as f32).to_index()).to_array();
                assert_eq!(read, index.map(|k| values[k as usize]), "{size} members");
            }
            // Past the set: a value of the column (a zero of its padding
            // where it is permuted, its last member where gathered)
            let beyond = F8::from_fn(|i| (size + i * 3) as f32).to_index();
            let padded: Vec<f32> = values.iter().copied().chain([0.0]).collect();
            assert!(column.get(beyond).to_array().iter().all(|v| padded.contains(v)), "{size} members");
        }
    }

    #[test]
    fn vectors_read_each_axis_by_the_same_index() {
        assert!(supported(), "the lanes need AVX2");
        let members: Vec<Vec3> = (0..11).map(|k| Vec3::new(k as f32, -(k as f32), k as f32 * 0.5)).collect();
        let column = Column3::new(members.iter().copied());
        let index: [i32; LANES] = [3, 10, 0, 7, 8, 2, 9, 1];
        let read = column.get(F8::from_fn(|i| index[i] as f32).to_index());
        for (lane, &k) in index.iter().enumerate() {
            assert_eq!(read.lane(lane), members[k as usize]);
        }
    }
}
