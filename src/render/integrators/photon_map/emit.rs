//! Where photons come from: every enabled light emits in proportion to its
//! power (`LightSource::emit`: point lights uniformly over the sphere, spot
//! lights within their cone weighted by the falloff, infinite lights from a
//! disc covering the scene, area lights from their surface with
//! cosine-weighted directions); caustic photons aim at specular objects.

use std::f32::consts::PI;

use glam::Vec3;

use crate::geometry::{offset_ray_origin, Frame, Ray};
use crate::render::world::emission::point_on_emitter;
use crate::render::world::light::{spot_factor, LightSource};
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::{uniform_cone, uniform_cone_pdf, uniform_sphere, uniform_sphere_pdf};
use crate::render::world::{ShapeRef, World};
use crate::scene::Rgb;

#[inline]
fn luminance(c: Rgb) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Picks lights in proportion to their power (luminance), so every photon
/// carries about the same power.
#[derive(Clone, Debug)]
pub struct LightPicker {
    cdf: Vec<f32>,
    total: f32,
}

impl LightPicker {
    pub fn new(world: &World) -> Self {
        let mut cdf = Vec::with_capacity(world.lights.len());
        let mut total = 0.0;
        for light in &world.lights {
            total += luminance(light.power(world.bounds())).max(0.0);
            cdf.push(total);
        }
        Self { cdf, total }
    }

    pub fn is_empty(&self) -> bool {
        self.total.is_nan() || self.total <= 0.0
    }

    /// The probability of picking light `index`.
    #[inline]
    pub fn probability(&self, index: usize) -> f32 {
        if self.is_empty() || index >= self.cdf.len() {
            return 0.0;
        }
        let previous = if index == 0 { 0.0 } else { self.cdf[index - 1] };
        (self.cdf[index] - previous) / self.total
    }

    /// (light index, probability of picking it).
    #[inline]
    pub fn pick(&self, u: f32) -> Option<(usize, f32)> {
        if self.is_empty() {
            return None;
        }
        let target = u * self.total;
        let index = self.cdf.partition_point(|c| *c <= target).min(self.cdf.len() - 1);
        let previous = if index == 0 { 0.0 } else { self.cdf[index - 1] };
        let probability = (self.cdf[index] - previous) / self.total;
        (probability > 0.0).then_some((index, probability))
    }
}

/// A photon leaving a light: its ray and power (W, before dividing by the
/// number of photons emitted).
#[derive(Clone, Copy, Debug)]
pub struct EmittedPhoton {
    pub ray: Ray,
    pub power: Rgb,
}

/// Emit one photon from a power-chosen light.
pub fn emit(world: &World, picker: &LightPicker, sampler: &mut Sampler) -> Option<EmittedPhoton> {
    let (index, pick) = picker.pick(sampler.next_f32())?;
    let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
    let emission = world.lights[index].emit(world.bounds(), u1, u2);
    Some(EmittedPhoton { ray: emission.ray, power: emission.power / pick })
}

/// Bounding spheres of the specular objects, the targets of caustic photons
/// (Jensen's projection maps, in their simplest form).
pub fn specular_targets(world: &World) -> Vec<(Vec3, f32)> {
    world
        .objects
        .iter()
        .filter(|o| crate::render::world::bsdf::Bsdf::new(&world.materials[o.material as usize]).is_specular())
        .filter(|o| !matches!(world.materials[o.material as usize], crate::scene::MaterialModel::Emissive { .. }))
        .filter_map(|o| match o.shape {
            ShapeRef::Sphere(i) => Some((world.spheres.center(i as usize), world.spheres.radius[i as usize])),
            ShapeRef::Triangle(t) => {
                let [a, b, c] = world.triangles[t as usize].0.vertices;
                let center = (a + b + c) / 3.0;
                let radius = (a - center).length().max((b - center).length()).max((c - center).length());
                Some((center, radius * 1.001))
            }
            ShapeRef::Plane(_) => None,
        })
        .collect()
}

/// Emit a photon aimed at one of the specular `targets`: a direction within
/// the cone a target's bounding sphere subtends from the emission point.
/// Its power divides by the pdf summed over every cone containing the
/// direction, so overlapping targets are not counted twice.
pub fn emit_toward(
    world: &World,
    picker: &LightPicker,
    targets: &[(Vec3, f32)],
    sampler: &mut Sampler,
) -> Option<EmittedPhoton> {
    if targets.is_empty() {
        return None;
    }
    let (index, pick) = picker.pick(sampler.next_f32())?;
    let light = &world.lights[index];
    let target = targets[((sampler.next_f32() * targets.len() as f32) as usize).min(targets.len() - 1)];
    let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
    let target_pick = 1.0 / targets.len() as f32;
    // Solid-angle pdf of choosing direction d from `origin`, over all targets
    let direction_pdf = |origin: Vec3, d: Vec3| -> f32 {
        targets
            .iter()
            .filter_map(|(center, radius)| {
                let to = *center - origin;
                let distance2 = to.length_squared();
                let sin2 = radius * radius / distance2;
                if sin2 >= 1.0 {
                    return None;
                }
                let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
                let cos = to.dot(d) / distance2.sqrt();
                (cos >= 1.0 - one_minus_cos).then(|| uniform_cone_pdf(one_minus_cos) * target_pick)
            })
            .sum()
    };
    let cone_direction = |origin: Vec3| -> Option<Vec3> {
        let to = target.0 - origin;
        let distance2 = to.length_squared();
        let sin2 = target.1 * target.1 / distance2;
        if sin2 >= 1.0 {
            return None;
        }
        let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
        Some(Frame::from_z(to / distance2.sqrt()).to_world(uniform_cone(u2, one_minus_cos)))
    };
    let (ray, power) = match *light {
        LightSource::Point { position, intensity, .. } => {
            let d = cone_direction(position)?;
            (Ray::new(position, d), intensity / direction_pdf(position, d))
        }
        LightSource::Spot { position, direction, cos_cone, exponent, intensity, .. } => {
            let d = cone_direction(position)?;
            let falloff = spot_factor(direction, d, cos_cone, exponent);
            if falloff == 0.0 {
                return None;
            }
            (Ray::new(position, d), intensity * (falloff / direction_pdf(position, d)))
        }
        LightSource::Directional { direction, irradiance } => {
            // A disc just covering the target, perpendicular to the light
            let frame = Frame::from_z(direction);
            let disc = crate::render::world::sampling::concentric_disk(u1) * target.1;
            let origin =
                target.0 - direction * (2.0 * world.bounds_radius.max(target.1)) + frame.x * disc.x + frame.y * disc.y;
            // Density of origins over all targets' discs containing this line
            let density: f32 = targets
                .iter()
                .filter(|(c, r)| {
                    let offset = *c - origin;
                    (offset - direction * offset.dot(direction)).length_squared() <= r * r
                })
                .map(|(_, r)| target_pick / (PI * r * r))
                .sum();
            (Ray::new(origin, direction), irradiance / density)
        }
        LightSource::Background { radiance } => {
            // A random sky direction, and a disc just covering the target across it
            let direction = -uniform_sphere(u2);
            let frame = Frame::from_z(direction);
            let disc = crate::render::world::sampling::concentric_disk(u1) * target.1;
            let origin =
                target.0 - direction * (2.0 * world.bounds_radius.max(target.1)) + frame.x * disc.x + frame.y * disc.y;
            let density: f32 = targets
                .iter()
                .filter(|(c, r)| {
                    let offset = *c - origin;
                    (offset - direction * offset.dot(direction)).length_squared() <= r * r
                })
                .map(|(_, r)| target_pick / (PI * r * r))
                .sum();
            (Ray::new(origin, direction), radiance / (uniform_sphere_pdf() * density))
        }
        LightSource::Area { radiance, ref emitter, .. } => {
            let (point, normal, error) = point_on_emitter(emitter, u1);
            let d = cone_direction(point)?;
            let cos = normal.dot(d);
            if cos <= 0.0 {
                return None;
            }
            let origin = offset_ray_origin(point, error, normal, d);
            let area = emitter.area();
            (Ray::new(origin, d), radiance * (cos * area / direction_pdf(point, d)))
        }
    };
    power.is_finite().then_some(EmittedPhoton { ray, power: power / pick })
}
