//! Light leaving the lights: where a photon or a light path starts, what it
//! carries, and the densities its sampling had. Multiple importance
//! sampling between paths from the camera and paths from the lights needs
//! those densities for any point on a light, not only sampled ones
//! (`emission_pdf`, `direct_pdf_a`). Infinite lights (directional, the
//! background) emit from a disc covering the region the camera sees, as far
//! behind it as its radius.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::light::{spot_factor, Emitter, LightSource};
use super::sampling::{concentric_disk, cosine_hemisphere, uniform_cone, uniform_cone_pdf, uniform_sphere};
use super::sampling::{uniform_sphere_pdf, uniform_triangle};
use crate::geometry::{offset_ray_origin, pow, Frame, Ray, SurfaceHit};
use crate::scene::Rgb;

/// The region infinite lights must light: a sphere about what the camera
/// sees (`World::cover`).
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub center: Vec3,
    pub radius: f32,
}

impl Bounds {
    /// Where light travelling along `direction` leaves the disc covering
    /// the region: `u` on the disc.
    fn disc_origin(&self, direction: Vec3, u: Vec2) -> Ray {
        let frame = Frame::from_z(direction);
        let disc = concentric_disk(u) * self.radius;
        let origin = self.center - direction * (2.0 * self.radius) + frame.x * disc.x + frame.y * disc.y;
        Ray::new(origin, direction)
    }

    /// The disc's density of origins, where the line through `point` along
    /// `direction` crosses it (0 outside: no light path from the disc
    /// reaches `point` that way).
    fn disc_pdf(&self, point: Vec3, direction: Vec3) -> f32 {
        let offset = point - self.center;
        let across = offset - direction * offset.dot(direction);
        if across.length_squared() <= self.radius * self.radius {
            1.0 / (PI * self.radius * self.radius)
        } else {
            0.0
        }
    }

    fn disc_area(&self) -> f32 {
        PI * self.radius * self.radius
    }
}

/// One start of light: its ray, what it carries, its densities.
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    pub ray: Ray,
    /// Emitted radiance times the cosine at the light over the densities
    /// (intensity for point and spot lights, irradiance for directional
    /// ones): a photon's power before it is divided by the photons emitted
    /// and by the light's pick probability.
    pub power: Rgb,
    /// Density of the start point (area; 1 for a point or spot light) times
    /// that of the direction (solid angle; 1 for a directional light).
    pub pdf: f32,
    /// Cosine between the direction and the light's normal (1 where it has none).
    pub cos: f32,
    /// The point it leaves from (an area light's, before the ray's offset;
    /// a point or spot light's position) and the light's normal there (zero
    /// where it has none).
    pub point: Vec3,
    pub normal: Vec3,
}

impl LightSource {
    /// Total emitted power.
    pub fn power(&self, bounds: Bounds) -> Rgb {
        match *self {
            LightSource::Point { intensity, .. } => intensity * (4.0 * PI),
            LightSource::Spot { intensity, cos_cone, exponent, .. } => {
                // ∫ over the cone of cos^σ θ dω = 2π (1 − cos^{σ+1} θc)/(σ + 1)
                intensity * (2.0 * PI * (1.0 - pow::powf(cos_cone, exponent + 1.0)) / (exponent + 1.0))
            }
            LightSource::Directional { irradiance, .. } => irradiance * bounds.disc_area(),
            LightSource::Area { radiance, ref emitter, .. } => radiance * (PI * emitter.area()),
            LightSource::Background { radiance } => radiance * (4.0 * PI * bounds.disc_area()),
        }
    }

    /// Whether it is at a finite distance (not directional, not the background).
    pub fn is_finite(&self) -> bool {
        !matches!(self, LightSource::Directional { .. } | LightSource::Background { .. })
    }

    /// Sample a start of light from two uniform pairs: `u1` for a point or
    /// spot light's direction, an area light's point, a directional light's
    /// disc and the background's direction; `u2` for an area light's
    /// direction and the background's disc.
    pub fn emit(&self, bounds: Bounds, u1: Vec2, u2: Vec2) -> Emission {
        match *self {
            LightSource::Point { position, intensity, .. } => Emission {
                ray: Ray::new(position, uniform_sphere(u1)),
                power: intensity * (4.0 * PI),
                pdf: uniform_sphere_pdf(),
                cos: 1.0,
                point: position,
                normal: Vec3::ZERO,
            },
            LightSource::Spot { position, direction, cos_cone, exponent, intensity, .. } => {
                let one_minus_cos = 1.0 - cos_cone;
                let d = Frame::from_z(direction).to_world(uniform_cone(u1, one_minus_cos));
                let falloff = spot_factor(direction, d, cos_cone, exponent);
                let pdf = uniform_cone_pdf(one_minus_cos);
                let power = intensity * (falloff / pdf);
                Emission { ray: Ray::new(position, d), power, pdf, cos: 1.0, point: position, normal: Vec3::ZERO }
            }
            LightSource::Directional { direction, irradiance } => {
                let ray = bounds.disc_origin(direction, u1);
                let (power, pdf) = (irradiance * bounds.disc_area(), 1.0 / bounds.disc_area());
                Emission { ray, power, pdf, cos: 1.0, point: ray.origin, normal: Vec3::ZERO }
            }
            LightSource::Background { radiance } => {
                // Light from every direction: it travels along −ω for a sky direction ω
                let direction = -uniform_sphere(u1);
                let ray = bounds.disc_origin(direction, u2);
                Emission {
                    ray,
                    power: radiance * (4.0 * PI * bounds.disc_area()),
                    pdf: uniform_sphere_pdf() / bounds.disc_area(),
                    cos: 1.0,
                    point: ray.origin,
                    normal: Vec3::ZERO,
                }
            }
            LightSource::Area { radiance, ref emitter, .. } => {
                let (point, normal, error) = point_on_emitter(emitter, u1);
                let local = cosine_hemisphere(u2);
                let d = Frame::from_z(normal).to_world(local);
                // Cosine-weighted: L cos θ / (pdf_area · cos θ/π) = π L A
                let origin = offset_ray_origin(point, error, normal, d);
                let area = emitter.area();
                Emission {
                    ray: Ray::new(origin, d),
                    power: radiance * (PI * area),
                    pdf: local.z / (PI * area),
                    cos: local.z,
                    point,
                    normal,
                }
            }
        }
    }

    /// The density `emit` has of starting at `point` (on the light, with its
    /// `normal`; ignored for infinite lights) and leaving along `direction`.
    pub fn emission_pdf(&self, bounds: Bounds, point: Vec3, normal: Vec3, direction: Vec3) -> f32 {
        match *self {
            LightSource::Point { .. } => uniform_sphere_pdf(),
            LightSource::Spot { direction: axis, cos_cone, .. } => {
                if axis.dot(direction) >= cos_cone {
                    uniform_cone_pdf(1.0 - cos_cone)
                } else {
                    0.0
                }
            }
            LightSource::Directional { .. } => bounds.disc_pdf(point, direction),
            LightSource::Background { .. } => uniform_sphere_pdf() * bounds.disc_pdf(point, direction),
            LightSource::Area { ref emitter, .. } => {
                let cos = normal.dot(direction);
                if cos <= 0.0 || !emitter.emits_at(point) {
                    return 0.0;
                }
                cos / (PI * emitter.area())
            }
        }
    }

    /// The density with which `sample` chooses the point `on_light` (with
    /// its `normal`) from `receiver`: per area for lights at a finite
    /// distance (1 for point and spot lights, whose position is certain),
    /// per solid angle for infinite ones (1 for a directional light).
    pub fn direct_pdf_a(&self, receiver: Vec3, on_light: Vec3, normal: Vec3) -> f32 {
        match *self {
            LightSource::Point { .. } | LightSource::Spot { .. } | LightSource::Directional { .. } => 1.0,
            LightSource::Background { .. } => uniform_sphere_pdf(),
            LightSource::Area { .. } => {
                let to_light = on_light - receiver;
                let distance2 = to_light.length_squared();
                let cos = normal.dot(-to_light) / distance2.sqrt();
                let hit = SurfaceHit { t: distance2.sqrt(), point: on_light, normal, error: 0.0 };
                self.pdf(receiver, &hit) * cos.max(0.0) / distance2
            }
        }
    }
}

/// A uniform point on an emitter: (point, normal, error bound).
pub fn point_on_emitter(emitter: &Emitter, u: Vec2) -> (Vec3, Vec3, f32) {
    match *emitter {
        Emitter::Sphere { center, radius, cap, .. } => {
            // Uniform over the emitting cap (the whole sphere when 1 − cos = 2)
            let normal =
                if cap.is_whole() { uniform_sphere(u) } else { cap.frame.to_world(uniform_cone(u, cap.one_minus_cos)) };
            (center + normal * radius, normal, emitter.error())
        }
        Emitter::Triangle { shape: ref triangle, .. } => {
            let (b0, b1) = uniform_triangle(u);
            let [a, b, c] = triangle.vertices;
            (a * b0 + b * b1 + c * (1.0 - b0 - b1), triangle.normal, emitter.error())
        }
    }
}
