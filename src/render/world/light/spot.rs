//! A spot light: a point light within a cone, its intensity falling off
//! as the thesis' (Vp·Va)^σ toward the cone's edge.

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3};

use super::{Aim, Light, LightSample, PointLight};
use crate::geometry::{pow, Frame, Ray, SurfaceHit};
use crate::render::world::emission::{Bounds, Emission};
use crate::render::world::sampling::{uniform_cone, uniform_cone_pdf};
use crate::scene::{Attenuation, Rgb};

#[derive(Clone, Copy, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    /// Its axis, the way it shines.
    pub direction: Vec3,
    pub cos_cone: f32,
    pub exponent: f32,
    pub intensity: Rgb,
    pub attenuation: Attenuation,
}

/// The thesis' spot factor: 0 outside the cone, (Vp·Va)^σ inside.
#[inline]
pub fn spot_factor(axis: Vec3, light_to_point: Vec3, cos_cone: f32, exponent: f32) -> f32 {
    let cos = axis.dot(light_to_point);
    if cos < cos_cone {
        0.0
    } else {
        pow::powf(cos, exponent)
    }
}

impl SpotLight {
    /// Its factor toward `light_to_point` (a unit vector).
    #[inline]
    fn factor(&self, light_to_point: Vec3) -> f32 {
        spot_factor(self.direction, light_to_point, self.cos_cone, self.exponent)
    }
}

impl Light for SpotLight {
    const DELTA: bool = true;
    const FINITE: bool = true;

    #[inline]
    fn sample(&self, at: &SurfaceHit, _u: Vec2) -> Option<LightSample> {
        let point = PointLight { position: self.position, intensity: self.intensity, attenuation: self.attenuation };
        point.sample_within(at, |light_to_point| self.factor(light_to_point))
    }

    fn power(&self, _bounds: Bounds) -> Rgb {
        let (cos_cone, exponent) = (self.cos_cone, self.exponent);
        // ∫ over the cone of cos^σ θ dω = 2π (1 − cos^{σ+1} θc)/(σ + 1)
        self.intensity * (2.0 * PI * (1.0 - pow::powf(cos_cone, exponent + 1.0)) / (exponent + 1.0))
    }

    fn emit(&self, _bounds: Bounds, u1: Vec2, _u2: Vec2) -> Emission {
        let one_minus_cos = 1.0 - self.cos_cone;
        let d = Frame::from_z(self.direction).to_world(uniform_cone(u1, one_minus_cos));
        let pdf = uniform_cone_pdf(one_minus_cos);
        let power = self.intensity * (self.factor(d) / pdf);
        Emission { ray: Ray::new(self.position, d), power, pdf, cos: 1.0, point: self.position, normal: Vec3::ZERO }
    }

    fn emission_pdf(&self, _bounds: Bounds, _point: Vec3, _normal: Vec3, direction: Vec3) -> f32 {
        if self.direction.dot(direction) >= self.cos_cone {
            uniform_cone_pdf(1.0 - self.cos_cone)
        } else {
            0.0
        }
    }

    fn direct_density(&self, sample: &LightSample, receiver: Vec3) -> (f32, f32) {
        ((sample.point - receiver).length_squared(), 1.0)
    }

    fn emit_toward(&self, aim: &dyn Aim, _u1: Vec2, _u2: Vec2) -> Option<(Ray, Rgb)> {
        let d = aim.direction_from(self.position)?;
        let falloff = self.factor(d);
        if falloff == 0.0 {
            return None;
        }
        Some((Ray::new(self.position, d), self.intensity * (falloff / aim.direction_pdf(self.position, d))))
    }

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool, _wall: u32) -> bool {
        holds(self.position.as_dvec3(), 0.0)
    }
}
