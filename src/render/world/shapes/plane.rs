//! An infinite plane: found by rays (`geometry::plane_t`), never sampled
//! as a light, since it has no finite area to draw from.

use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct PlaneShape {
    pub normal: Vec3,
    pub offset: f32,
    pub object: u32,
}
