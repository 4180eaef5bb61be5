//! Light sources as the renderer samples them, one file per kind: delta
//! lights (`point`, `spot`, `directional`), area lights on emissive shapes
//! (`area`) and the background. Each answers the `Light` trait, what every
//! algorithm asks of a light (sampled toward a point, started from for
//! photons and light paths, and the densities of both); `LightSource` is
//! the closed enum they dispatch through. Each carries what it is sampled
//! on, so sampling needs nothing else.

mod area;
mod background;
mod directional;
mod point;
mod spot;

use glam::{DVec3, Vec2, Vec3};

use super::emission::{Bounds, Emission};
pub use super::shapes::Emitter;
use super::shapes::EmitterCap;
use crate::geometry::{Ray, SurfaceHit};
use crate::scene::{self, LightKind, Rgb};
pub use area::AreaLight;
pub use background::BackgroundLight;
pub use directional::DirectionalLight;
pub use point::PointLight;
pub use spot::{spot_factor, SpotLight};

/// What every algorithm asks of a kind of light, written once in its file.
pub trait Light {
    /// Whether its light comes from a point or a direction, which no ray
    /// can hit (its pdf is infinite).
    const DELTA: bool;
    /// Whether it lies at a finite distance (not directional, not the background).
    const FINITE: bool;

    /// Sample light arriving at `at` (a surface hit, for its offset origin).
    fn sample(&self, at: &SurfaceHit, u: Vec2) -> Option<LightSample>;

    /// Solid-angle pdf with which `sample` would have chosen the point
    /// `hit` from `p` (for MIS on BSDF-sampled hits; 0 where no ray can hit
    /// the light).
    fn pdf(&self, _p: Vec3, _hit: &SurfaceHit) -> f32 {
        0.0
    }

    /// Total emitted power (infinite lights over `bounds`' cover).
    fn power(&self, bounds: Bounds) -> Rgb;

    /// A start of light from two uniform pairs: `u1` for a point or spot
    /// light's direction, an area light's point, a directional light's
    /// cover and the background's direction; `u2` for an area light's
    /// direction and the background's cover.
    fn emit(&self, bounds: Bounds, u1: Vec2, u2: Vec2) -> Emission;

    /// The density `emit` has of starting at `point` (on the light, with
    /// its `normal`; ignored for infinite lights) and leaving along
    /// `direction`.
    fn emission_pdf(&self, bounds: Bounds, point: Vec3, normal: Vec3, direction: Vec3) -> f32;

    /// The density with which `sample` chooses the point `on_light` (with
    /// its `normal`) from `receiver`: per area for lights at a finite
    /// distance, per solid angle for infinite ones; 1 where the point is
    /// certain (point and spot lights) or the direction is (a directional
    /// light).
    fn direct_pdf_a(&self, _receiver: Vec3, _on_light: Vec3, _normal: Vec3) -> f32 {
        1.0
    }

    /// For a `sample` taken at `receiver`: the density bidirectional
    /// weights use for it (`direct_pdf_a`'s measure, from the sample), and
    /// the cosine at the light.
    fn direct_density(&self, sample: &LightSample, receiver: Vec3) -> (f32, f32);

    /// A start of light aimed as `aim` says (caustic photons), from the
    /// uniform pairs `u1`, `u2`: its ray and its power, or `None` where
    /// the aim cannot be met.
    fn emit_toward(&self, aim: &dyn Aim, u1: Vec2, u2: Vec2) -> Option<(Ray, Rgb)>;

    /// Whether every sample it can give lies in a region, given as
    /// `holds(centre, reach)` (whether that ball lies in it), the inside of
    /// the wall `wall`.
    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool, wall: u32) -> bool;
}

/// Where light is aimed when it must reach a few targets (photon mapping's
/// caustic photons, Jensen's projection maps).
pub trait Aim {
    /// A direction from `origin` toward a target, `None` from within one.
    fn direction_from(&self, origin: Vec3) -> Option<Vec3>;

    /// The solid-angle density of `direction_from` choosing `direction`
    /// from `origin`, over every target.
    fn direction_pdf(&self, origin: Vec3, direction: Vec3) -> f32;

    /// For light along `direction` from infinitely far: where it starts
    /// (upstream of a target) and the density of starts over every target
    /// holding its line.
    fn upstream(&self, direction: Vec3) -> (Vec3, f32);
}

/// A light of the world, one variant per kind (each in its own file).
#[derive(Clone, Debug)]
pub enum LightSource {
    Point(PointLight),
    Spot(SpotLight),
    Directional(DirectionalLight),
    Area(AreaLight),
    Background(BackgroundLight),
}

/// `$body` for the light, whatever its kind, as `$light`.
macro_rules! on_light {
    ($source:expr, $light:ident => $body:expr) => {
        match $source {
            LightSource::Point($light) => $body,
            LightSource::Spot($light) => $body,
            LightSource::Directional($light) => $body,
            LightSource::Area($light) => $body,
            LightSource::Background($light) => $body,
        }
    };
}

/// Whether a kind of light is a delta (its `Light::DELTA`).
fn delta_of<L: Light>(_: &L) -> bool {
    L::DELTA
}

/// Whether a kind of light is finite (its `Light::FINITE`).
fn finite_of<L: Light>(_: &L) -> bool {
    L::FINITE
}

impl LightSource {
    /// A light of the scene, as the renderer samples it (area lights and
    /// the background come from objects and the scene's sky instead).
    pub fn of(light: &scene::Light) -> Self {
        let power = light.color * light.intensity;
        match light.kind {
            LightKind::Point { position } => {
                LightSource::Point(PointLight { position, intensity: power, attenuation: light.attenuation })
            }
            LightKind::Directional { direction } => {
                LightSource::Directional(DirectionalLight { direction: direction.normalize(), irradiance: power })
            }
            LightKind::Spot { position, direction, cone_angle_degrees, falloff_exponent } => {
                LightSource::Spot(SpotLight {
                    position,
                    direction: direction.normalize(),
                    cos_cone: cone_angle_degrees.to_radians().cos(),
                    exponent: falloff_exponent,
                    intensity: power,
                    attenuation: light.attenuation,
                })
            }
        }
    }

    pub fn is_delta(&self) -> bool {
        on_light!(self, light => delta_of(light))
    }

    /// Whether it is at a finite distance (not directional, not the background).
    pub fn is_finite(&self) -> bool {
        on_light!(self, light => finite_of(light))
    }

    /// `Light::sample`.
    #[inline]
    pub fn sample(&self, at: &SurfaceHit, u: Vec2) -> Option<LightSample> {
        on_light!(self, light => light.sample(at, u))
    }

    /// `Light::pdf`.
    #[inline]
    pub fn pdf(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        on_light!(self, light => light.pdf(p, hit))
    }

    /// `Light::power`.
    pub fn power(&self, bounds: Bounds) -> Rgb {
        on_light!(self, light => light.power(bounds))
    }

    /// `Light::emit`.
    pub fn emit(&self, bounds: Bounds, u1: Vec2, u2: Vec2) -> Emission {
        on_light!(self, light => light.emit(bounds, u1, u2))
    }

    /// `Light::emission_pdf`.
    pub fn emission_pdf(&self, bounds: Bounds, point: Vec3, normal: Vec3, direction: Vec3) -> f32 {
        on_light!(self, light => light.emission_pdf(bounds, point, normal, direction))
    }

    /// `Light::direct_pdf_a`.
    pub fn direct_pdf_a(&self, receiver: Vec3, on_light: Vec3, normal: Vec3) -> f32 {
        on_light!(self, light => light.direct_pdf_a(receiver, on_light, normal))
    }

    /// `Light::direct_density`.
    pub fn direct_density(&self, sample: &LightSample, receiver: Vec3) -> (f32, f32) {
        on_light!(self, light => light.direct_density(sample, receiver))
    }

    /// `Light::emit_toward`.
    pub fn emit_toward(&self, aim: &dyn Aim, u1: Vec2, u2: Vec2) -> Option<(Ray, Rgb)> {
        on_light!(self, light => light.emit_toward(aim, u1, u2))
    }

    /// `Light::held_by`.
    pub fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool, wall: u32) -> bool {
        on_light!(self, light => light.held_by(holds, wall))
    }

    /// The emitting sphere's cap, for a light on a sphere.
    pub fn cap(&self) -> Option<EmitterCap> {
        match self {
            LightSource::Area(AreaLight { emitter: Emitter::Sphere { shape, .. }, .. }) => Some(shape.cap),
            _ => None,
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Frame, Triangle};
    use crate::render::world::camera::CameraModel;
    use crate::render::world::rng::Sampler;
    use crate::render::world::World;
    use crate::scene::Attenuation;

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
        let point = LightSource::Point(PointLight { position, intensity, attenuation });
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
        let spot = |cos_cone| {
            LightSource::Spot(SpotLight { position, direction: axis, cos_cone, exponent: 3.0, intensity, attenuation })
        };
        let sample = spot(0.8).sample(&at, Vec2::ZERO).expect("inside the cone");
        assert!(close(sample.value, intensity * att * 0.9f32.powi(3)), "{:?}", sample.value);
        assert!(spot(0.95).sample(&at, Vec2::ZERO).is_none());
        let directional = LightSource::Directional(DirectionalLight { direction: -Vec3::Y, irradiance: intensity });
        let background = LightSource::Background(BackgroundLight { radiance: intensity });
        let shape = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Z);
        let area = LightSource::Area(AreaLight {
            object: 0,
            radiance: intensity,
            emitter: Emitter::Triangle { triangle: 0, shape },
        });
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
        let light = LightSource::Area(AreaLight {
            object: 0,
            radiance: Rgb::ONE,
            emitter: Emitter::Triangle { triangle: 0, shape },
        });
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
