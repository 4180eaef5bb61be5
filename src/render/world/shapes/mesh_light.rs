//! An emissive mesh as one light: a triangle drawn in proportion to its
//! area by an alias table, then a point uniform on it, so a point's
//! density is one over the mesh's area wherever it lies and a sample costs
//! the same for ten triangles or a million.

use glam::{DVec3, Vec2, Vec3};

use super::{solid_angle_pdf, AreaEmitter};
use crate::geometry::{SurfaceHit, Triangle};
use crate::render::world::alias::AliasTable;

#[derive(Clone, Debug)]
pub struct MeshEmitter {
    /// Its triangles, degenerate ones with no chance of being drawn.
    triangles: Vec<Triangle>,
    by_area: AliasTable,
    area: f32,
    /// The largest of its triangles' error bounds.
    error: f32,
}

impl MeshEmitter {
    /// Of `triangles`; `None` when they have no area.
    pub fn new(triangles: &[Triangle]) -> Option<Self> {
        let areas: Vec<f64> =
            triangles.iter().map(|t| if t.is_degenerate() { 0.0 } else { Triangle::area(t) as f64 }).collect();
        let by_area = AliasTable::new(&areas)?;
        let area = areas.iter().sum::<f64>() as f32;
        let error = triangles.iter().map(AreaEmitter::error).fold(0.0, f32::max);
        Some(Self { triangles: triangles.to_vec(), by_area, area, error })
    }
}

impl AreaEmitter for MeshEmitter {
    fn area(&self) -> f32 {
        self.area
    }

    fn emits_at(&self, _point: Vec3) -> bool {
        true
    }

    fn error(&self) -> f32 {
        self.error
    }

    /// A triangle by area, then a point uniform on it.
    fn uniform_point(&self, u: Vec2) -> (Vec3, Vec3) {
        let (k, u0) = self.by_area.sample(u.x);
        self.triangles[k].uniform_point(Vec2::new(u0, u.y))
    }

    fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let (point, normal) = self.uniform_point(u);
        let pdf = solid_angle_pdf(p, point, normal, self.area);
        (pdf > 0.0).then_some((point, normal, pdf))
    }

    fn pdf_from(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        solid_angle_pdf(p, hit.point, hit.normal, self.area)
    }

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool) -> bool {
        self.triangles.iter().all(|t| t.held_by(holds))
    }
}
