//! A point light: intensity I from one point in every direction, falling
//! off with the scene's attenuation (the thesis' 1/(a·d² + b·d + c)).

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3};

use super::{Aim, Light, LightSample};
use crate::geometry::{Ray, SurfaceHit};
use crate::render::world::emission::{Bounds, Emission};
use crate::render::world::sampling::{uniform_sphere, uniform_sphere_pdf};
use crate::scene::{Attenuation, Rgb};

#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Rgb,
    pub attenuation: Attenuation,
}

impl PointLight {
    /// Its light arriving at `at`, times `factor` of the way it leaves the
    /// light (a spot's cone); `None` where that is 0.
    #[inline]
    pub(super) fn sample_within(&self, at: &SurfaceHit, factor: impl Fn(Vec3) -> f32) -> Option<LightSample> {
        let (shadow, shadow_t_max) = at.spawn_ray_to(self.position, 0.0);
        let d = (self.position - at.point).length();
        let factor = factor(-shadow.direction);
        if factor == 0.0 {
            return None;
        }
        let value = self.intensity * (self.attenuation.factor(d) * factor);
        Some(LightSample::delta(shadow, shadow_t_max, value, self.position))
    }
}

impl Light for PointLight {
    const DELTA: bool = true;
    const FINITE: bool = true;

    #[inline]
    fn sample(&self, at: &SurfaceHit, _u: Vec2) -> Option<LightSample> {
        self.sample_within(at, |_| 1.0)
    }

    fn power(&self, _bounds: Bounds) -> Rgb {
        self.intensity * (4.0 * PI)
    }

    fn emit(&self, _bounds: Bounds, u1: Vec2, _u2: Vec2) -> Emission {
        Emission {
            ray: Ray::new(self.position, uniform_sphere(u1)),
            power: self.intensity * (4.0 * PI),
            pdf: uniform_sphere_pdf(),
            cos: 1.0,
            point: self.position,
            normal: Vec3::ZERO,
        }
    }

    fn emission_pdf(&self, _bounds: Bounds, _point: Vec3, _normal: Vec3, _direction: Vec3) -> f32 {
        uniform_sphere_pdf()
    }

    fn direct_density(&self, sample: &LightSample, receiver: Vec3) -> (f32, f32) {
        ((sample.point - receiver).length_squared(), 1.0)
    }

    fn emit_toward(&self, aim: &dyn Aim, _u1: Vec2, _u2: Vec2) -> Option<(Ray, Rgb)> {
        let d = aim.direction_from(self.position)?;
        Some((Ray::new(self.position, d), self.intensity / aim.direction_pdf(self.position, d)))
    }

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool, _wall: u32) -> bool {
        holds(self.position.as_dvec3(), 0.0)
    }
}
