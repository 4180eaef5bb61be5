//! Light sampling in eight lanes: area lights (sphere caps, whole spheres
//! and triangles), points, spots and directional lights in the lanes, the
//! background through the scalar code lane by lane.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::geometry::{frame_from_z, offset_origin, ray_to, to_world, SurfaceHit};
use crate::render::world::lanes::{self, F8, LANES, M8, V8};
use crate::render::world::light::{self, Emitter, LightSource};
use crate::render::world::sampling::{cosine_hemisphere_of, uniform_cone_of, uniform_cone_pdf_of};
use crate::render::world::sampling::{uniform_sphere_of, uniform_triangle_of};
use crate::render::world::shapes::sphere::{sphere_cone_normal_of, CappedSphere};
use crate::render::world::shapes::{solid_angle_pdf_of, triangle::triangle_point_of};
use crate::render::world::World;
use crate::scene::{Attenuation, Rgb};

/// An area light as the lanes draw it (`sample_area`).
#[derive(Clone, Copy, Debug)]
enum LaneLight {
    /// The emitting cap of a sphere partly hidden (smallpt's light in its
    /// ceiling), uniform over its area.
    Cap(CapLight),
    /// A whole sphere, uniform over the cone it subtends.
    Sphere(SphereLight),
    /// A triangle, uniform over its area.
    Triangle(TriangleLight),
    /// A point light, or a spot (a point light with a cone).
    Point(PointLight),
    /// Light from one direction.
    Directional(DirectionalLight),
}

#[derive(Clone, Copy, Debug)]
struct CapLight {
    center: Vec3,
    radius: f32,
    error: f32,
    frame: [Vec3; 3],
    one_minus_cos: f32,
    area: f32,
    radiance: Rgb,
}

#[derive(Clone, Copy, Debug)]
struct SphereLight {
    center: Vec3,
    radius: f32,
    error: f32,
    area: f32,
    radiance: Rgb,
}

#[derive(Clone, Copy, Debug)]
struct TriangleLight {
    vertices: [Vec3; 3],
    normal: Vec3,
    area: f32,
    error: f32,
    radiance: Rgb,
}

/// A spot's cone (a point light's takes every direction: cos_cone −∞).
#[derive(Clone, Copy, Debug)]
struct PointLight {
    position: Vec3,
    intensity: Rgb,
    /// The attenuation's a, b, c: 1/(a·d² + b·d + c).
    attenuation: [f32; 3],
    axis: Vec3,
    cos_cone: f32,
    exponent: f32,
}

#[derive(Clone, Copy, Debug)]
struct DirectionalLight {
    direction: Vec3,
    irradiance: Rgb,
}

impl LaneLight {
    /// The light the lanes draw for `light`, if they draw it.
    fn new(light: &LightSource) -> Option<Self> {
        let point = |position, intensity, attenuation: Attenuation, axis, cos_cone, exponent| {
            let attenuation = [attenuation.a, attenuation.b, attenuation.c];
            Some(LaneLight::Point(PointLight { position, intensity, attenuation, axis, cos_cone, exponent }))
        };
        let (radiance, emitter) = match *light {
            LightSource::Area(light::AreaLight { radiance, ref emitter, .. }) => (radiance, emitter.clone()),
            LightSource::Point(light::PointLight { position, intensity, attenuation }) => {
                return point(position, intensity, attenuation, Vec3::Z, f32::NEG_INFINITY, 0.0);
            }
            LightSource::Spot(light::SpotLight { position, direction, cos_cone, exponent, intensity, attenuation }) => {
                return point(position, intensity, attenuation, direction, cos_cone, exponent);
            }
            LightSource::Directional(light::DirectionalLight { direction, irradiance }) => {
                return Some(LaneLight::Directional(DirectionalLight { direction, irradiance }));
            }
            LightSource::Background { .. } => return None,
        };
        let (error, area) = (emitter.error(), emitter.area());
        Some(match emitter {
            Emitter::Sphere { shape: CappedSphere { center, radius, cap }, .. } if cap.is_whole() => {
                LaneLight::Sphere(SphereLight { center, radius, error, area, radiance })
            }
            Emitter::Sphere { shape: CappedSphere { center, radius, cap }, .. } => LaneLight::Cap(CapLight {
                center,
                radius,
                error,
                frame: [cap.frame.x, cap.frame.y, cap.frame.z],
                one_minus_cos: cap.one_minus_cos,
                area,
                radiance,
            }),
            Emitter::Triangle { shape, .. } => LaneLight::Triangle(TriangleLight {
                vertices: shape.vertices,
                normal: shape.normal,
                area,
                error,
                radiance,
            }),
            Emitter::Mesh(_) => return None,
        })
    }

    fn cap(&self) -> Option<&CapLight> {
        match self {
            LaneLight::Cap(cap) => Some(cap),
            _ => None,
        }
    }

    fn sphere(&self) -> Option<&SphereLight> {
        match self {
            LaneLight::Sphere(sphere) => Some(sphere),
            _ => None,
        }
    }

    fn triangle(&self) -> Option<&TriangleLight> {
        match self {
            LaneLight::Triangle(triangle) => Some(triangle),
            _ => None,
        }
    }

    fn point(&self) -> Option<&PointLight> {
        match self {
            LaneLight::Point(point) => Some(point),
            _ => None,
        }
    }

    fn directional(&self) -> Option<&DirectionalLight> {
        match self {
            LaneLight::Directional(directional) => Some(directional),
            _ => None,
        }
    }
}

/// The scene's lights as the lanes sample them, with what every sample
/// would otherwise look up again.
#[derive(Clone, Debug)]
pub(crate) struct LaneLights {
    /// Each light of the world, `None` for those sampled lane by lane.
    lights: Vec<Option<LaneLight>>,
    /// Whether every light is of one kind the lanes draw (then every lane
    /// draws that kind).
    one_kind: bool,
    /// Of each kind, its lights (their indices): one is splat, two are
    /// blended, more are gathered lane by lane.
    of_kind: [Vec<usize>; 5],
}

impl LaneLights {
    pub(super) fn new(world: &World) -> Self {
        let lights: Vec<_> = world.lights.iter().map(LaneLight::new).collect();
        let of_kind = |kind: fn(&LaneLight) -> bool| -> Vec<usize> {
            (0..lights.len()).filter(|&i| lights[i].as_ref().is_some_and(kind)).collect()
        };
        let of_kind = [
            of_kind(|light| light.cap().is_some()),
            of_kind(|light| light.sphere().is_some()),
            of_kind(|light| light.triangle().is_some()),
            of_kind(|light| light.point().is_some()),
            of_kind(|light| light.directional().is_some()),
        ];
        LaneLights {
            one_kind: lights.iter().all(Option::is_some) && of_kind.iter().filter(|k| !k.is_empty()).count() == 1,
            of_kind,
            lights,
        }
    }

    /// The one light's point for the draw `u`, where the scene has one light
    /// and the point does not depend on what it lights (a cap, a triangle):
    /// drawn before the hit is known, its work overlaps the hit's.
    #[inline(always)]
    pub(crate) fn drawn_ahead(&self, u: (F8, F8)) -> Option<OnLight> {
        match &self.lights[..] {
            [Some(LaneLight::Cap(cap))] => Some(on_caps(&PerLane::One(cap), u)),
            [Some(LaneLight::Triangle(triangle))] => Some(on_triangles(&PerLane::One(triangle), u)),
            _ => None,
        }
    }

    /// The lanes of `mask` whose light is of one kind (`kind`, the `which`th
    /// kind), and their lights; `None` if there are no such lanes.
    #[inline(always)]
    fn of_kind<'a, T>(
        &'a self,
        pick: &[usize; LANES],
        mask: M8,
        which: usize,
        kind: fn(&LaneLight) -> Option<&T>,
    ) -> Option<(M8, PerLane<'a, T>)> {
        let indices = &self.of_kind[which];
        let first = self.lights[*indices.first()?].as_ref().and_then(kind)?;
        let lane_kind = |i: usize| self.lights[pick[i]].as_ref().and_then(kind);
        let lanes = match self.one_kind {
            true => mask,
            false => M8::from_fn(|i| lane_kind(i).is_some()).and(mask),
        };
        if !lanes.any() {
            return None;
        }
        // Lanes of another kind compute on the first light of this one, unused
        Some((
            lanes,
            match indices[..] {
                [_] => PerLane::One(first),
                [_, second_index] => match self.lights[second_index].as_ref().and_then(kind) {
                    Some(second) => PerLane::Two(first, second, M8::from_fn(|i| pick[i] == second_index)),
                    None => PerLane::One(first),
                },
                _ => PerLane::Each(lanes::each(|i| lane_kind(i).unwrap_or(first))),
            },
        ))
    }
}

/// Each lane's light of one kind: the only light of its kind, splat; one
/// of two (the second in the lanes of the mask: a quad light's triangles),
/// blended; or each lane's own, gathered.
enum PerLane<'a, T> {
    One(&'a T),
    Two(&'a T, &'a T, M8),
    Each([&'a T; LANES]),
}

impl<T> PerLane<'_, T> {
    #[inline(always)]
    fn f8(&self, field: impl Fn(&T) -> f32) -> F8 {
        match self {
            PerLane::One(light) => F8::splat(field(light)),
            PerLane::Two(first, second, lanes) => lanes.select(F8::splat(field(second)), F8::splat(field(first))),
            PerLane::Each(lights) => F8::from_fn(|i| field(lights[i])),
        }
    }

    #[inline(always)]
    fn v8(&self, field: impl Fn(&T) -> Vec3) -> V8 {
        match self {
            PerLane::One(light) => V8::splat(field(light)),
            PerLane::Two(first, second, lanes) => lanes.select_v(V8::splat(field(second)), V8::splat(field(first))),
            PerLane::Each(lights) => V8::from_fn(|i| field(lights[i])),
        }
    }
}

/// Points drawn on the lights of some lanes, before the shadow ray: the
/// point, the light's normal there, its error bound, the solid-angle pdf at
/// the shading point and the radiance.
struct Drawn {
    target: V8,
    normal: V8,
    error: F8,
    pdf: F8,
    radiance: V8,
}

impl Drawn {
    /// `self` in the lanes of `mask`, `before` elsewhere (if any).
    #[inline(always)]
    fn over(self, mask: M8, before: Option<Drawn>) -> Drawn {
        let Some(b) = before else { return self };
        Drawn {
            target: V8::select(mask, self.target, b.target),
            normal: V8::select(mask, self.normal, b.normal),
            error: mask.select(self.error, b.error),
            pdf: mask.select(self.pdf, b.pdf),
            radiance: V8::select(mask, self.radiance, b.radiance),
        }
    }
}

impl OnLight {
    /// The draw as seen from `p`: its solid-angle pdf there.
    #[inline(always)]
    fn seen_from(self, p: V8) -> Drawn {
        let pdf = solid_angle_pdf_of(p, self.point, self.normal, self.area);
        Drawn { target: self.point, normal: self.normal, error: self.error, pdf, radiance: self.radiance }
    }
}

/// Uniform over each lane's cap (`sample_area`).
#[inline(always)]
fn on_caps(caps: &PerLane<CapLight>, u: (F8, F8)) -> OnLight {
    // Written out: `array::from_fn` is left out of line, without AVX2
    let frame = [caps.v8(|cap| cap.frame[0]), caps.v8(|cap| cap.frame[1]), caps.v8(|cap| cap.frame[2])];
    let normal = to_world(frame, uniform_cone_of(u.0, u.1, caps.f8(|cap| cap.one_minus_cos)));
    OnLight {
        point: caps.v8(|cap| cap.center) + normal * caps.f8(|cap| cap.radius),
        normal,
        error: caps.f8(|cap| cap.error),
        area: caps.f8(|cap| cap.area),
        radiance: caps.v8(|cap| cap.radiance),
    }
}

/// Uniform over the cone each lane's sphere subtends, the point where the
/// direction meets the sphere (`sample_area`); pdf 0 from inside it.
#[inline(always)]
fn draw_on_spheres(spheres: &PerLane<SphereLight>, p: V8, u: (F8, F8)) -> Drawn {
    let (center, radius) = (spheres.v8(|sphere| sphere.center), spheres.f8(|sphere| sphere.radius));
    let one = F8::splat(1.0);
    let to_center = center - p;
    let distance2 = to_center.length_squared();
    let sin2_max = radius * radius / distance2;
    let one_minus_cos = sin2_max / (one + (one - sin2_max).sqrt());
    let axis = to_center / distance2.sqrt();
    let normal = sphere_cone_normal_of(axis, sin2_max, one_minus_cos, u.0, u.1);
    Drawn {
        target: center + normal * radius,
        normal,
        error: spheres.f8(|sphere| sphere.error),
        pdf: sin2_max.lt(one).select(uniform_cone_pdf_of(one_minus_cos), F8::splat(0.0)),
        radiance: spheres.v8(|sphere| sphere.radiance),
    }
}

/// Each lane's triangle's corners. Written out: a closure over the corner
/// index is left out of line, without AVX2.
#[inline(always)]
fn triangle_vertices(triangles: &PerLane<TriangleLight>) -> [V8; 3] {
    [
        triangles.v8(|triangle| triangle.vertices[0]),
        triangles.v8(|triangle| triangle.vertices[1]),
        triangles.v8(|triangle| triangle.vertices[2]),
    ]
}

/// Uniform over each lane's triangle (`sample_area`).
#[inline(always)]
fn on_triangles(triangles: &PerLane<TriangleLight>, u: (F8, F8)) -> OnLight {
    let (b0, b1) = uniform_triangle_of(u.0, u.1);
    OnLight {
        point: triangle_point_of(triangle_vertices(triangles), b0, b1),
        normal: triangles.v8(|triangle| triangle.normal),
        error: triangles.f8(|triangle| triangle.error),
        area: triangles.f8(|triangle| triangle.area),
        radiance: triangles.v8(|triangle| triangle.radiance),
    }
}

/// Light samples in eight lanes (only lanes of the mask are meaningful).
pub(crate) struct LightLanes {
    pub(crate) valid: M8,
    pub(crate) delta: M8,
    pub(crate) wi: V8,
    /// Radiance over pdf (or the delta light's irradiance).
    pub(crate) value: V8,
    pub(crate) pdf: F8,
    pub(crate) origin: V8,
    pub(crate) t_max: F8,
    /// The point drawn and the light's normal there (`LightSample::point`
    /// and `normal`): what bidirectional methods weigh a sample by.
    pub(crate) point: V8,
    pub(crate) light_normal: V8,
}

impl LightLanes {
    /// A delta light's samples in the lanes of `lanes`, `valid` those it
    /// lights, from `point` (the origin for a directional light).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn set(&mut self, lanes: M8, valid: M8, wi: V8, value: V8, origin: V8, t_max: F8, point: V8) {
        self.valid = lanes.select_mask(valid, self.valid);
        self.delta = self.delta.or(lanes);
        self.wi = lanes.select_v(wi, self.wi);
        self.value = lanes.select_v(value, self.value);
        self.pdf = lanes.select(F8::splat(f32::INFINITY), self.pdf);
        self.origin = lanes.select_v(origin, self.origin);
        self.t_max = lanes.select(t_max, self.t_max);
        self.point = lanes.select_v(point, self.point);
        self.light_normal = lanes.select_v(V8::splat(Vec3::ZERO), self.light_normal);
    }

    /// `LightSource::sample` for each lane's light: all but the background
    /// in the lanes.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn sample(
        lights: &LaneLights,
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        point: V8,
        normal: V8,
        error: F8,
        u: (F8, F8),
        ahead: Option<OnLight>,
        hit: &impl Fn(usize) -> SurfaceHit,
    ) -> LightLanes {
        let mut out = LightLanes {
            valid: M8::NONE,
            delta: M8::NONE,
            wi: V8::splat(Vec3::Z),
            value: V8::splat(Vec3::ZERO),
            pdf: F8::splat(0.0),
            origin: point,
            t_max: F8::splat(0.0),
            point: V8::splat(Vec3::ZERO),
            light_normal: V8::splat(Vec3::ZERO),
        };
        let (mut drawn, mut in_lanes) = (None, M8::NONE);
        if let Some(on_light) = ahead {
            // The one light, its point drawn ahead
            (drawn, in_lanes) = (Some(on_light.seen_from(point)), mask);
        } else {
            if let Some((lanes, caps)) = lights.of_kind(pick, mask, 0, LaneLight::cap) {
                drawn = Some(on_caps(&caps, u).seen_from(point).over(lanes, drawn));
                in_lanes = in_lanes.or(lanes);
            }
            if let Some((lanes, spheres)) = lights.of_kind(pick, mask, 1, LaneLight::sphere) {
                drawn = Some(draw_on_spheres(&spheres, point, u).over(lanes, drawn));
                in_lanes = in_lanes.or(lanes);
            }
            if let Some((lanes, triangles)) = lights.of_kind(pick, mask, 2, LaneLight::triangle) {
                drawn = Some(on_triangles(&triangles, u).seen_from(point).over(lanes, drawn));
                in_lanes = in_lanes.or(lanes);
            }
        }
        if let Some(Drawn { target, normal: light_normal, error: light_error, pdf, radiance }) = drawn {
            // The shadow ray (`SurfaceHit::spawn_ray_to`)
            let (origin, wi, t_max) = ray_to(point, error, normal, target, light_error);
            // Emission is one-sided: the light's front must face the point
            let faces = !light_normal.dot(-wi).le(F8::splat(0.0));
            let valid = in_lanes.and(pdf.gt(F8::splat(0.0))).and(faces);
            let value = radiance / pdf;
            out = LightLanes { valid, delta: M8::NONE, wi, value, pdf, origin, t_max, point: target, light_normal };
        }
        if let Some((lanes, points)) = lights.of_kind(pick, mask, 3, LaneLight::point) {
            let position = points.v8(|light| light.position);
            let (origin, wi, t_max) = ray_to(point, error, normal, position, F8::splat(0.0));
            let distance = (position - point).length();
            let coefficient = |k: usize| points.f8(|light| light.attenuation[k]);
            let (a, b, c) = (coefficient(0), coefficient(1), coefficient(2));
            let attenuation = F8::splat(1.0) / (a * distance * distance + b * distance + c);
            // The spot's factor (`spot_factor`): 0 outside the cone, where
            // the light gives no sample
            let cos = points.v8(|light| light.axis).dot(-wi);
            let exponent = points.f8(|light| light.exponent);
            let spot = cos.lt(points.f8(|light| light.cos_cone)).select(F8::splat(0.0), cos.powf(exponent));
            let value = points.v8(|light| light.intensity) * (attenuation * spot);
            let valid = lanes.and_not(spot.eq(F8::splat(0.0)));
            out.set(lanes, valid, wi, value, origin, t_max, position);
            in_lanes = in_lanes.or(lanes);
        }
        if let Some((lanes, directionals)) = lights.of_kind(pick, mask, 4, LaneLight::directional) {
            let wi = -directionals.v8(|light| light.direction);
            let origin = offset_origin(point, error, normal, wi);
            let value = directionals.v8(|light| light.irradiance);
            out.set(lanes, lanes, wi, value, origin, F8::splat(f32::INFINITY), V8::splat(Vec3::ZERO));
            in_lanes = in_lanes.or(lanes);
        }
        let others = mask.and_not(in_lanes);
        for lane in others.lanes() {
            let light = &world.lights[pick[lane]];
            let u = Vec2::new(u.0.lane(lane), u.1.lane(lane));
            if let Some(sample) = light.sample(&hit(lane), u) {
                out.valid.set(lane, true);
                out.delta.set(lane, light.is_delta());
                out.wi.set_lane(lane, sample.wi);
                out.value.set_lane(lane, sample.value);
                out.pdf.set_lane(lane, sample.pdf);
                out.origin.set_lane(lane, sample.shadow.origin);
                out.t_max.set_lane(lane, sample.shadow_t_max);
                out.point.set_lane(lane, sample.point);
                out.light_normal.set_lane(lane, sample.normal);
            }
        }
        out
    }
}

/// Starts of light in eight lanes (`LightSource::emit`): where each leaves,
/// along what, carrying what (before the light's pick probability).
pub(crate) struct EmittedLanes {
    pub(crate) origin: V8,
    pub(crate) direction: V8,
    pub(crate) power: V8,
}

/// Points drawn uniformly on area lights: before their direction (light
/// leaving them), or before the point they light is known (on caps and
/// triangles the draw does not depend on it).
pub(crate) struct OnLight {
    point: V8,
    normal: V8,
    error: F8,
    area: F8,
    radiance: V8,
}

impl OnLight {
    #[inline(always)]
    fn over(self, mask: M8, before: Option<OnLight>) -> OnLight {
        let Some(b) = before else { return self };
        OnLight {
            point: mask.select_v(self.point, b.point),
            normal: mask.select_v(self.normal, b.normal),
            error: mask.select(self.error, b.error),
            area: mask.select(self.area, b.area),
            radiance: mask.select_v(self.radiance, b.radiance),
        }
    }
}

impl LaneLights {
    /// `LightSource::emit` for each lane's light (`pick`), in the lanes of
    /// `mask`: area lights and point lights in the lanes; spots,
    /// directional lights and the background lane by lane.
    #[inline(always)]
    pub(super) fn emit(
        &self,
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        u1: (F8, F8),
        u2: (F8, F8),
    ) -> EmittedLanes {
        let mut out =
            EmittedLanes { origin: V8::splat(Vec3::ZERO), direction: V8::splat(Vec3::Z), power: V8::splat(Vec3::ZERO) };
        let (mut on_light, mut in_lanes) = (None, M8::NONE);
        // A point uniform over the light's area (`point_on_emitter`)
        if let Some((lanes, caps)) = self.of_kind(pick, mask, 0, LaneLight::cap) {
            on_light = Some(on_caps(&caps, u1).over(lanes, on_light));
            in_lanes = in_lanes.or(lanes);
        }
        if let Some((lanes, spheres)) = self.of_kind(pick, mask, 1, LaneLight::sphere) {
            let normal = uniform_sphere_of(u1.0, u1.1);
            let point = spheres.v8(|sphere| sphere.center) + normal * spheres.f8(|sphere| sphere.radius);
            let (error, area) = (spheres.f8(|sphere| sphere.error), spheres.f8(|sphere| sphere.area));
            let radiance = spheres.v8(|sphere| sphere.radiance);
            on_light = Some(OnLight { point, normal, error, area, radiance }.over(lanes, on_light));
            in_lanes = in_lanes.or(lanes);
        }
        if let Some((lanes, triangles)) = self.of_kind(pick, mask, 2, LaneLight::triangle) {
            on_light = Some(on_triangles(&triangles, u1).over(lanes, on_light));
            in_lanes = in_lanes.or(lanes);
        }
        if let Some(OnLight { point, normal, error, area, radiance }) = on_light {
            // Cosine-weighted about the normal: L cos θ / (pdf_area · cos θ/π) = π L A
            let direction = to_world(frame_from_z(normal), cosine_hemisphere_of(u2.0, u2.1));
            out.origin = offset_origin(point, error, normal, direction);
            out.direction = direction;
            out.power = radiance * (F8::splat(PI) * area);
        }
        // Point lights, not spots: uniform over the sphere of directions
        if let Some((lanes, points)) = self.of_kind(pick, mask, 3, LaneLight::point) {
            let lanes = lanes.and(points.f8(|light| light.cos_cone).eq(F8::splat(f32::NEG_INFINITY)));
            if lanes.any() {
                out.origin = lanes.select_v(points.v8(|light| light.position), out.origin);
                out.direction = lanes.select_v(uniform_sphere_of(u1.0, u1.1), out.direction);
                out.power = lanes.select_v(points.v8(|light| light.intensity) * F8::splat(4.0 * PI), out.power);
                in_lanes = in_lanes.or(lanes);
            }
        }
        for lane in mask.and_not(in_lanes).lanes() {
            let u = |(u0, u1): (F8, F8)| Vec2::new(u0.lane(lane), u1.lane(lane));
            let emission = world.lights[pick[lane]].emit(world.bounds(), u(u1), u(u2));
            out.origin.set_lane(lane, emission.ray.origin);
            out.direction.set_lane(lane, emission.ray.direction);
            out.power.set_lane(lane, emission.power);
        }
        out
    }
}
