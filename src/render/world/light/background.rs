//! The scene's background: radiance arriving from every direction that
//! escapes, sampled uniformly over the sphere. Its light starts, like a
//! directional light's, on a rectangle covering the seen region's shadow.

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3};

use super::{Aim, Light, LightSample};
use crate::geometry::{Ray, SurfaceHit};
use crate::render::world::emission::{Bounds, Emission};
use crate::render::world::sampling::{uniform_sphere, uniform_sphere_pdf};
use crate::scene::Rgb;

#[derive(Clone, Copy, Debug)]
pub struct BackgroundLight {
    pub radiance: Rgb,
}

impl Light for BackgroundLight {
    const DELTA: bool = false;
    const FINITE: bool = false;

    #[inline]
    fn sample(&self, at: &SurfaceHit, u: Vec2) -> Option<LightSample> {
        let pdf = uniform_sphere_pdf();
        let shadow = at.spawn_ray(uniform_sphere(u));
        Some(LightSample {
            wi: shadow.direction,
            value: self.radiance / pdf,
            pdf,
            shadow,
            shadow_t_max: f32::INFINITY,
            on_triangle: None,
            on_sphere: None,
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
        })
    }

    /// Over the mean cover, taken as the box's mean shadow: a quarter of
    /// its surface, by Cauchy.
    fn power(&self, bounds: Bounds) -> Rgb {
        self.radiance * (4.0 * PI * bounds.mean_shadow())
    }

    fn emit(&self, bounds: Bounds, u1: Vec2, u2: Vec2) -> Emission {
        // Light from every direction: it travels along −ω for a sky direction ω
        let direction = -uniform_sphere(u1);
        let (ray, area) = bounds.start(direction, u2);
        Emission {
            ray,
            power: self.radiance * (4.0 * PI * area),
            pdf: if area > 0.0 { uniform_sphere_pdf() / area } else { 0.0 },
            cos: 1.0,
            point: ray.origin,
            normal: Vec3::ZERO,
        }
    }

    fn emission_pdf(&self, bounds: Bounds, point: Vec3, _normal: Vec3, direction: Vec3) -> f32 {
        uniform_sphere_pdf() * bounds.start_pdf(point, direction)
    }

    fn direct_pdf_a(&self, _receiver: Vec3, _on_light: Vec3, _normal: Vec3) -> f32 {
        uniform_sphere_pdf()
    }

    fn direct_density(&self, sample: &LightSample, _receiver: Vec3) -> (f32, f32) {
        (sample.pdf, 1.0)
    }

    fn emit_toward(&self, aim: &dyn Aim, _u1: Vec2, u2: Vec2) -> Option<(Ray, Rgb)> {
        // A random sky direction
        let direction = -uniform_sphere(u2);
        let (origin, density) = aim.upstream(direction);
        Some((Ray::new(origin, direction), self.radiance / (uniform_sphere_pdf() * density)))
    }

    fn held_by(&self, _holds: &dyn Fn(DVec3, f64) -> bool, _wall: u32) -> bool {
        false
    }
}
