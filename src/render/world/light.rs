//! Light sources as the renderer samples them: delta lights (point, spot,
//! directional) and emissive spheres and triangles (area lights). Each
//! carries the geometry it is sampled on, so sampling needs nothing else.

use glam::{Vec2, Vec3};

use super::sampling::{uniform_sphere, uniform_sphere_pdf};
pub use super::shapes::Emitter;
use super::shapes::EmitterCap;
use crate::faults::{self, Fault};
use crate::geometry::{pow, Ray, SurfaceHit};
use crate::scene::{Attenuation, Rgb};

#[derive(Clone, Debug)]
pub enum LightSource {
    Point {
        position: Vec3,
        intensity: Rgb,
        attenuation: Attenuation,
    },
    Spot {
        position: Vec3,
        direction: Vec3,
        cos_cone: f32,
        exponent: f32,
        intensity: Rgb,
        attenuation: Attenuation,
    },
    /// `direction` is the way the light travels.
    Directional {
        direction: Vec3,
        irradiance: Rgb,
    },
    Area {
        object: u32,
        radiance: Rgb,
        emitter: Emitter,
    },
    /// The scene's background: radiance arriving from every direction
    /// that escapes, sampled uniformly over the sphere.
    Background {
        radiance: Rgb,
    },
}

/// One sampled light path segment from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Irradiance at normal incidence for delta lights; radiance over the
    /// solid-angle pdf for area lights. Either way: multiply by f·|cos θ|.
    pub value: Rgb,
    /// Solid-angle pdf (for MIS), infinite for delta lights.
    pub pdf: f32,
    /// The shadow ray and how far it may go.
    pub shadow: Ray,
    pub shadow_t_max: f32,
    /// The triangle the sample lies on: its shadow ray meets that plane only at its end.
    pub on_triangle: Option<u32>,
    /// The sphere the sample lies on (facing the point): its shadow ray meets it only at its end.
    pub on_sphere: Option<u32>,
    /// The sampled point and the light's normal there (an area light's;
    /// a point or spot light's position and no normal; nothing for
    /// infinite lights): what bidirectional methods weigh the sample by.
    pub point: Vec3,
    pub normal: Vec3,
}

impl LightSample {
    /// From a delta light: an infinite pdf, no surface under the sample.
    #[inline]
    fn delta(shadow: Ray, shadow_t_max: f32, value: Rgb, point: Vec3) -> Self {
        LightSample {
            wi: shadow.direction,
            value,
            pdf: f32::INFINITY,
            shadow,
            shadow_t_max,
            on_triangle: None,
            on_sphere: None,
            point,
            normal: Vec3::ZERO,
        }
    }
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

impl LightSource {
    pub fn is_delta(&self) -> bool {
        !matches!(self, LightSource::Area { .. } | LightSource::Background { .. })
    }

    /// Sample light arriving at `at` (a surface hit, for its offset origin).
    #[inline]
    pub fn sample(&self, at: &SurfaceHit, u: Vec2) -> Option<LightSample> {
        let p = at.point;
        match *self {
            LightSource::Point { position, intensity, attenuation } => {
                let (shadow, shadow_t_max) = at.spawn_ray_to(position, 0.0);
                let d = (position - p).length();
                Some(LightSample::delta(shadow, shadow_t_max, intensity * attenuation.factor(d), position))
            }
            LightSource::Spot { position, direction, cos_cone, exponent, intensity, attenuation } => {
                let (shadow, shadow_t_max) = at.spawn_ray_to(position, 0.0);
                let d = (position - p).length();
                let factor = spot_factor(direction, -shadow.direction, cos_cone, exponent);
                if factor == 0.0 {
                    return None;
                }
                Some(LightSample::delta(shadow, shadow_t_max, intensity * (attenuation.factor(d) * factor), position))
            }
            LightSource::Directional { direction, irradiance } => {
                Some(LightSample::delta(at.spawn_ray(-direction), f32::INFINITY, irradiance, Vec3::ZERO))
            }
            LightSource::Background { radiance } => {
                let pdf = uniform_sphere_pdf();
                let shadow = at.spawn_ray(uniform_sphere(u));
                Some(LightSample {
                    wi: shadow.direction,
                    value: radiance / pdf,
                    pdf,
                    shadow,
                    shadow_t_max: f32::INFINITY,
                    on_triangle: None,
                    on_sphere: None,
                    point: Vec3::ZERO,
                    normal: Vec3::ZERO,
                })
            }
            LightSource::Area { radiance, ref emitter, .. } => {
                let (target, normal, error, pdf) = emitter.sample_from(p, u)?;
                let (shadow, shadow_t_max) = at.spawn_ray_to(target, error);
                // Emission is one-sided: the light's front must face the point
                if normal.dot(-shadow.direction) <= 0.0 || pdf.is_nan() || pdf <= 0.0 {
                    return None;
                }
                let (on_triangle, on_sphere) = match *emitter {
                    Emitter::Triangle { triangle, .. } => (Some(triangle), None),
                    Emitter::Sphere { sphere, .. } => (None, Some(sphere)),
                };
                Some(LightSample {
                    wi: shadow.direction,
                    value: radiance / pdf,
                    pdf,
                    shadow,
                    shadow_t_max,
                    on_triangle,
                    on_sphere,
                    point: target,
                    normal,
                })
            }
        }
    }
}

impl LightSource {
    /// Solid-angle pdf with which `sample` would have chosen the point `hit`
    /// from `p` (for MIS on BSDF-sampled hits of an area light; 0 otherwise).
    #[inline]
    pub fn pdf(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        let pdf = self.area_pdf(p, hit);
        if faults::active(Fault::LightPdfOff) {
            pdf * 1.25
        } else {
            pdf
        }
    }

    #[inline]
    fn area_pdf(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        let LightSource::Area { emitter, .. } = self else { return 0.0 };
        emitter.pdf_from(p, hit)
    }

    /// The emitting sphere's cap, for a light on a sphere.
    pub fn cap(&self) -> Option<EmitterCap> {
        match self {
            LightSource::Area { emitter: Emitter::Sphere { shape, .. }, .. } => Some(shape.cap),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Frame, Triangle};
    use crate::render::world::camera::CameraModel;
    use crate::render::world::rng::Sampler;
    use crate::render::world::World;

    /// Point and spot lights give I·att(d) (times the spot factor) toward
    /// the light, with an infinite pdf; a spot gives nothing outside its
    /// cone. Only area lights and the background are not deltas.
    #[test]
    fn delta_lights_give_their_closed_forms() {
        let at = SurfaceHit { t: 1.0, point: Vec3::new(0.5, -1.0, 2.0), normal: Vec3::Y, error: 0.0 };
        let position = Vec3::new(1.5, 2.0, 0.0);
        let (d, wi) = ((position - at.point).length(), (position - at.point).normalize());
        let (intensity, attenuation) = (Rgb::new(3.0, 2.0, 1.0), Attenuation { a: 1.0, b: 0.5, c: 0.25 });
        let att = 1.0 / (d * d + 0.5 * d + 0.25);
        let close = |a: Rgb, b: Rgb| (a - b).abs().max_element() <= 1e-5 * b.max_element();
        let point = LightSource::Point { position, intensity, attenuation };
        let sample = point.sample(&at, Vec2::ZERO).expect("a point light always samples");
        // (the shadow ray starts a hair off the surface)
        assert!(
            close(sample.value, intensity * att) && (sample.wi - wi).length() < 1e-4,
            "{:?} {}",
            sample.value,
            sample.wi
        );
        assert_eq!((sample.pdf, sample.point), (f32::INFINITY, position));
        // A spot aimed past the point: cos 0.9 off its axis, exponent 3
        let axis = Frame::from_z(-wi).to_world(Vec3::new((1.0f32 - 0.81).sqrt(), 0.0, 0.9));
        let spot =
            |cos_cone| LightSource::Spot { position, direction: axis, cos_cone, exponent: 3.0, intensity, attenuation };
        let sample = spot(0.8).sample(&at, Vec2::ZERO).expect("inside the cone");
        assert!(close(sample.value, intensity * att * 0.9f32.powi(3)), "{:?}", sample.value);
        assert!(spot(0.95).sample(&at, Vec2::ZERO).is_none());
        let directional = LightSource::Directional { direction: -Vec3::Y, irradiance: intensity };
        let background = LightSource::Background { radiance: intensity };
        let shape = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Z);
        let area =
            LightSource::Area { object: 0, radiance: intensity, emitter: Emitter::Triangle { triangle: 0, shape } };
        let deltas: Vec<bool> =
            [point, spot(0.8), directional, background, area].iter().map(LightSource::is_delta).collect();
        assert_eq!(deltas, [true, true, true, false, false]);
    }

    /// Area lights emit from their front only: a point behind a triangle
    /// light gets no sample from it, one in front does.
    #[test]
    fn an_area_light_lights_only_its_front() {
        // Normal (b − a) × (c − a) = +y
        let shape = Triangle::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
        assert!(shape.normal.y > 0.99);
        let light =
            LightSource::Area { object: 0, radiance: Rgb::ONE, emitter: Emitter::Triangle { triangle: 0, shape } };
        let hit = |y: f32| SurfaceHit { t: 1.0, point: Vec3::new(0.3, y, 0.3), normal: Vec3::Y, error: 0.0 };
        let mut sampler = Sampler::new(3, 0, 5);
        for _ in 0..100 {
            let u = sampler.next_2d();
            assert!(light.sample(&hit(-1.0), u).is_none(), "lit from behind");
            let front = light.sample(&hit(1.0), u).expect("lit in front");
            assert!(front.pdf > 0.0 && front.value.is_finite() && front.wi.y < 0.0);
        }
    }

    /// smallpt's light is a sphere of radius 600 poking 0.27 through the
    /// ceiling. Light samples taken in the room land on the part under the
    /// ceiling and reach the light; sampling the light's part near the room
    /// instead had 98% of them blocked by the ceiling.
    #[test]
    fn smallpt_light_samples_land_under_the_ceiling() {
        let scene = crate::scene::presets::preset("smallpt").and_then(Result::ok).expect("smallpt preset");
        let (world, _) = World::for_view(&scene, &CameraModel::new(&scene.camera, 64, 48), 64, 48);
        let ceiling = world.shapes.spheres.center(5).as_dvec3();
        let mut s = Sampler::new(0, 0, 600);
        let (mut taken, mut reached) = (0, 0);
        for _ in 0..2000 {
            // A point on whatever is below a random spot in the room
            let above = Vec3::new(5.0 + 90.0 * s.next_f32(), 60.0, 10.0 + 140.0 * s.next_f32());
            let Some(hit) = world.intersect(&Ray::new(above, -Vec3::Y), f32::INFINITY) else { continue };
            let Some(sample) = world.lights[0].sample(&hit.surface, s.next_2d()) else { continue };
            let target = sample.shadow.at(sample.shadow_t_max).as_dvec3();
            assert!((target - ceiling).length() < 1.0e5 + 0.05, "a sample above the ceiling: {target}");
            taken += 1;
            reached += !world.occluded(&sample.shadow, sample.shadow_t_max) as u32;
        }
        assert!(taken > 1500 && reached as f32 > 0.75 * taken as f32, "{reached} of {taken} samples reached the light");
    }

    #[test]
    fn spot_cone_edge_is_where_cos_says() {
        let axis = -Vec3::Y;
        let cone = 30.0f32.to_radians();
        let inside = Vec3::new((cone - 1e-3).sin(), -(cone - 1e-3).cos(), 0.0);
        let outside = Vec3::new((cone + 1e-3).sin(), -(cone + 1e-3).cos(), 0.0);
        assert!(spot_factor(axis, inside, cone.cos(), 0.0) == 1.0);
        assert!(spot_factor(axis, outside, cone.cos(), 0.0) == 0.0);
        assert!((spot_factor(axis, inside, cone.cos(), 2.0) - (cone - 1e-3).cos().powi(2)).abs() < 1e-6);
        assert_eq!(spot_factor(axis, axis, 1.0, 1.0e4), 1.0);
    }
}
