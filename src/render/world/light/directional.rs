//! A directional light (a sun): irradiance E arriving along one direction
//! everywhere. Its light starts on a rectangle covering the shadow of the
//! region the camera sees (`Bounds`).

use glam::{DVec3, Vec2, Vec3};

use super::{Aim, Light, LightSample};
use crate::geometry::{Ray, SurfaceHit};
use crate::render::world::emission::{Bounds, Emission};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug)]
pub struct DirectionalLight {
    /// The way the light travels.
    pub direction: Vec3,
    pub irradiance: Rgb,
}

impl Light for DirectionalLight {
    const DELTA: bool = true;
    const FINITE: bool = false;

    #[inline]
    fn sample(&self, at: &SurfaceHit, _u: Vec2) -> Option<LightSample> {
        Some(LightSample::delta(at.spawn_ray(-self.direction), f32::INFINITY, self.irradiance, Vec3::ZERO))
    }

    fn power(&self, bounds: Bounds) -> Rgb {
        self.irradiance * bounds.area(self.direction)
    }

    fn emit(&self, bounds: Bounds, u1: Vec2, _u2: Vec2) -> Emission {
        let (ray, area) = bounds.start(self.direction, u1);
        let (power, pdf) = (self.irradiance * area, if area > 0.0 { 1.0 / area } else { 0.0 });
        Emission { ray, power, pdf, cos: 1.0, point: ray.origin, normal: Vec3::ZERO }
    }

    fn emission_pdf(&self, bounds: Bounds, point: Vec3, _normal: Vec3, direction: Vec3) -> f32 {
        bounds.start_pdf(point, direction)
    }

    fn direct_density(&self, _sample: &LightSample, _receiver: Vec3) -> (f32, f32) {
        (1.0, 1.0)
    }

    fn emit_toward(&self, aim: &dyn Aim, _u1: Vec2, _u2: Vec2) -> Option<(Ray, Rgb)> {
        let (origin, density) = aim.upstream(self.direction);
        Some((Ray::new(origin, self.direction), self.irradiance / density))
    }

    fn held_by(&self, _holds: &dyn Fn(DVec3, f64) -> bool, _wall: u32) -> bool {
        false
    }
}
