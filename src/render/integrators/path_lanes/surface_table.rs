//! Every shape's surface as the lanes read it: a column a field
//! (`lanes::Column`), indexed by shape.

use glam::Vec3;

use super::Surface;
use crate::render::world::lanes::{Column, Column3};

/// Every shape's surface (spheres, then planes, then triangles): the
/// records, and a column per field for the lanes to read eight at a time.
#[derive(Clone, Debug)]
pub(super) struct SurfaceTable {
    pub(super) records: Vec<Surface>,
    pub(super) kind: Column,
    pub(super) color: Column3,
    pub(super) ior: Column,
    pub(super) specular: Column3,
    pub(super) exponent: Column,
    pub(super) diffuse_probability: Column,
    pub(super) normalisation: Column,
}

impl SurfaceTable {
    pub(super) fn new(records: Vec<Surface>) -> Self {
        let column = |field: fn(&Surface) -> f32| Column::new(records.iter().map(field));
        let column3 = |field: fn(&Surface) -> Vec3| Column3::new(records.iter().map(field));
        SurfaceTable {
            kind: column(|s| s.kind),
            color: column3(|s| s.color),
            ior: column(|s| s.ior),
            specular: column3(|s| s.specular),
            exponent: column(|s| s.exponent),
            diffuse_probability: column(|s| s.diffuse_probability),
            normalisation: column(|s| s.normalisation),
            records,
        }
    }
}
