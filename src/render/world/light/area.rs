//! An area light: a shape (`shapes::Emitter`) emitting radiance L from its
//! front, sampled where the shape's kind says (`shapes::AreaEmitter`).

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3};

use super::{Aim, Light, LightSample};
use crate::faults::{self, Fault};
use crate::geometry::{offset_ray_origin, Frame, Ray, SurfaceHit};
use crate::render::world::emission::{Bounds, Emission};
use crate::render::world::sampling::cosine_hemisphere;
use crate::render::world::shapes::Emitter;
use crate::scene::Rgb;

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The object it is.
    pub object: u32,
    pub radiance: Rgb,
    pub emitter: Emitter,
}

impl Light for AreaLight {
    const DELTA: bool = false;
    const FINITE: bool = true;

    #[inline]
    fn sample(&self, at: &SurfaceHit, u: Vec2) -> Option<LightSample> {
        let (target, normal, error, pdf) = self.emitter.sample_from(at.point, u)?;
        let (shadow, shadow_t_max) = at.spawn_ray_to(target, error);
        // Emission is one-sided: the light's front must face the point
        if normal.dot(-shadow.direction) <= 0.0 || pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        // A shadow ray toward a lone triangle skips its plane (the seam of a
        // panel in a ceiling); toward a mesh nothing: it stops short of the
        // point by the error margin (`ray_to`), and the mesh's other
        // triangles may rightly block it
        let (on_triangle, on_sphere) = match self.emitter {
            Emitter::Triangle { triangle, .. } => (Some(triangle), None),
            Emitter::Sphere { sphere, .. } => (None, Some(sphere)),
            Emitter::Mesh(_) => (None, None),
        };
        Some(LightSample {
            wi: shadow.direction,
            value: self.radiance / pdf,
            pdf,
            shadow,
            shadow_t_max,
            on_triangle,
            on_sphere,
            point: target,
            normal,
        })
    }

    #[inline]
    fn pdf(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        let pdf = self.emitter.pdf_from(p, hit);
        if faults::active(Fault::LightPdfOff) {
            pdf * 1.25
        } else {
            pdf
        }
    }

    fn power(&self, _bounds: Bounds) -> Rgb {
        self.radiance * (PI * self.emitter.area())
    }

    fn emit(&self, _bounds: Bounds, u1: Vec2, u2: Vec2) -> Emission {
        let (point, normal, error) = self.emitter.uniform_point(u1);
        let local = cosine_hemisphere(u2);
        let d = Frame::from_z(normal).to_world(local);
        // Cosine-weighted: L cos θ / (pdf_area · cos θ/π) = π L A
        let origin = offset_ray_origin(point, error, normal, d);
        let area = self.emitter.area();
        Emission {
            ray: Ray::new(origin, d),
            power: self.radiance * (PI * area),
            pdf: local.z / (PI * area),
            cos: local.z,
            point,
            normal,
        }
    }

    fn emission_pdf(&self, _bounds: Bounds, point: Vec3, normal: Vec3, direction: Vec3) -> f32 {
        let cos = normal.dot(direction);
        if cos <= 0.0 || !self.emitter.emits_at(point) {
            return 0.0;
        }
        cos / (PI * self.emitter.area())
    }

    fn direct_pdf_a(&self, receiver: Vec3, on_light: Vec3, normal: Vec3) -> f32 {
        let to_light = on_light - receiver;
        let distance2 = to_light.length_squared();
        let cos = normal.dot(-to_light) / distance2.sqrt();
        let hit = SurfaceHit { t: distance2.sqrt(), point: on_light, normal, error: 0.0 };
        self.pdf(receiver, &hit) * cos.max(0.0) / distance2
    }

    fn direct_density(&self, sample: &LightSample, _receiver: Vec3) -> (f32, f32) {
        (sample.pdf, sample.normal.dot(-sample.wi))
    }

    fn emit_toward(&self, aim: &dyn Aim, u1: Vec2, _u2: Vec2) -> Option<(Ray, Rgb)> {
        let (point, normal, error) = self.emitter.uniform_point(u1);
        let d = aim.direction_from(point)?;
        let cos = normal.dot(d);
        if cos <= 0.0 {
            return None;
        }
        let origin = offset_ray_origin(point, error, normal, d);
        let area = self.emitter.area();
        Some((Ray::new(origin, d), self.radiance * (cos * area / aim.direction_pdf(point, d))))
    }

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool, wall: u32) -> bool {
        match self.emitter {
            // Cut to this wall's inside: in it by construction
            Emitter::Sphere { shape, .. } if shape.cap.wall == Some(wall) => true,
            _ => self.emitter.held_by(holds),
        }
    }
}
