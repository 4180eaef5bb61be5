//! The scene's shapes in flat arrays, by kind: what the hit loops and the
//! occluders read.

use glam::Vec3;

use super::spheres::SphereLanes;

/// Which flat array an object's shape lives in, and where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeRef {
    Sphere(u32),
    Plane(u32),
    Triangle(u32),
}

#[derive(Clone, Copy, Debug)]
pub struct ObjectInfo {
    pub shape: ShapeRef,
    pub material: u32,
    /// Index into `World::lights` when the object is a sampled area light.
    pub light: Option<u32>,
}

/// Spheres as parallel arrays: the hit loop reads only what it needs.
#[derive(Clone, Debug, Default)]
pub struct Spheres {
    pub center_x: Vec<f32>,
    pub center_y: Vec<f32>,
    pub center_z: Vec<f32>,
    pub radius: Vec<f32>,
    pub object: Vec<u32>,
    /// The same spheres four to a SIMD group, for the hit loops.
    pub lanes: SphereLanes,
}

impl Spheres {
    #[inline]
    pub fn center(&self, i: usize) -> Vec3 {
        Vec3::new(self.center_x[i], self.center_y[i], self.center_z[i])
    }
}

#[derive(Clone, Copy, Debug)]
pub struct PlaneShape {
    pub normal: Vec3,
    pub offset: f32,
    pub object: u32,
}
