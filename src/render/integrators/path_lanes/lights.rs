//! Light sampling in eight lanes: sphere caps (smallpt's light) and
//! triangles computed in the lanes, any other light through the scalar code
//! lane by lane.

use glam::{Vec2, Vec3};

use crate::geometry::{ray_to, to_world, SurfaceHit};
use crate::render::world::lanes::{self, F8, LANES, M8, V8};
use crate::render::world::light::{solid_angle_pdf_of, triangle_point_of};
use crate::render::world::sampling::{uniform_cone_of, uniform_triangle_of};
use crate::render::world::World;
use crate::scene::Rgb;

/// An area light the lanes sample (`LightSource::sample` of an area light);
/// other lights the scalar code samples lane by lane.
#[derive(Clone, Copy, Debug)]
pub(super) enum LaneLight {
    /// A sphere light's emitting cap, uniform over its area.
    Cap(CapLight),
    /// A triangle light, uniform over its area.
    Triangle(TriangleLight),
}

#[derive(Clone, Copy, Debug)]
pub(super) struct CapLight {
    pub(super) center: Vec3,
    pub(super) radius: f32,
    pub(super) error: f32,
    pub(super) frame: [Vec3; 3],
    pub(super) one_minus_cos: f32,
    pub(super) area: f32,
    pub(super) radiance: Rgb,
}

impl CapLight {
    /// Where the lanes' lights hold none.
    const NONE: CapLight = CapLight {
        center: Vec3::ZERO,
        radius: 0.0,
        error: 0.0,
        frame: [Vec3::X, Vec3::Y, Vec3::Z],
        one_minus_cos: 0.0,
        area: 0.0,
        radiance: Vec3::ZERO,
    };
}

#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleLight {
    pub(super) vertices: [Vec3; 3],
    pub(super) normal: Vec3,
    pub(super) area: f32,
    pub(super) error: f32,
    pub(super) radiance: Rgb,
}

impl TriangleLight {
    /// Where the lanes' lights hold none.
    const NONE: TriangleLight =
        TriangleLight { vertices: [Vec3::ZERO; 3], normal: Vec3::Z, area: 0.0, error: 0.0, radiance: Vec3::ZERO };
}

/// Points drawn on the lights of some lanes, before the shadow ray.
struct Drawn {
    target: V8,
    normal: V8,
    error: F8,
    area: F8,
    radiance: V8,
}

impl Drawn {
    /// `a` in the lanes of `mask`, `b` elsewhere.
    #[inline(always)]
    fn select(mask: M8, a: Drawn, b: Drawn) -> Drawn {
        Drawn {
            target: V8::select(mask, a.target, b.target),
            normal: V8::select(mask, a.normal, b.normal),
            error: mask.select(a.error, b.error),
            area: mask.select(a.area, b.area),
            radiance: V8::select(mask, a.radiance, b.radiance),
        }
    }
}

/// The scene's lights as the lanes sample them, with what every sample
/// would otherwise look up again.
#[derive(Clone, Debug)]
pub(super) struct LaneLights {
    /// Each light of the world, `None` for those sampled lane by lane.
    lights: Vec<Option<LaneLight>>,
    /// The first cap and the first triangle, and whether it is the only one
    /// of its kind.
    first_cap: Option<(CapLight, bool)>,
    first_triangle: Option<(TriangleLight, bool)>,
    all_in_lanes: bool,
}

impl LaneLights {
    pub(super) fn new(lights: Vec<Option<LaneLight>>) -> Self {
        fn first<T: Copy>(mut of_kind: impl Iterator<Item = T>) -> Option<(T, bool)> {
            let first = of_kind.next()?;
            Some((first, of_kind.next().is_none()))
        }
        LaneLights {
            first_cap: first(lights.iter().flatten().filter_map(LaneLight::cap)),
            first_triangle: first(lights.iter().flatten().filter_map(LaneLight::triangle)),
            all_in_lanes: lights.iter().all(Option::is_some),
            lights,
        }
    }
}

impl LaneLight {
    fn cap(&self) -> Option<CapLight> {
        match *self {
            LaneLight::Cap(cap) => Some(cap),
            LaneLight::Triangle(_) => None,
        }
    }

    fn triangle(&self) -> Option<TriangleLight> {
        match *self {
            LaneLight::Triangle(triangle) => Some(triangle),
            LaneLight::Cap(_) => None,
        }
    }
}

/// Each lane's light of one kind: the one light of that kind, splat, or
/// each lane's own, lanes of another kind computing on the first light of
/// this kind, unused.
enum PerLane<T> {
    One(T),
    Each([T; LANES]),
}

impl<T: Copy> PerLane<T> {
    #[inline(always)]
    fn of(
        lights: &LaneLights,
        pick: &[usize; LANES],
        (first, only): (T, bool),
        kind: impl Fn(&LaneLight) -> Option<T>,
    ) -> Self {
        match only {
            true => PerLane::One(first),
            false => PerLane::Each(lanes::each(|i| lights.lights[pick[i]].as_ref().and_then(&kind).unwrap_or(first))),
        }
    }

    #[inline(always)]
    fn f8(&self, field: impl Fn(&T) -> f32) -> F8 {
        match self {
            PerLane::One(light) => F8::splat(field(light)),
            PerLane::Each(lights) => F8::from_fn(|i| field(&lights[i])),
        }
    }

    #[inline(always)]
    fn v8(&self, field: impl Fn(&T) -> Vec3) -> V8 {
        match self {
            PerLane::One(light) => V8::splat(field(light)),
            PerLane::Each(lights) => V8::from_fn(|i| field(&lights[i])),
        }
    }
}

/// Uniform over each lane's cap (`sample_area`).
#[inline(always)]
fn draw_on_caps(caps: &PerLane<CapLight>, u: (F8, F8)) -> Drawn {
    // Written out: `array::from_fn` is left out of line, without AVX2
    let frame = [caps.v8(|cap| cap.frame[0]), caps.v8(|cap| cap.frame[1]), caps.v8(|cap| cap.frame[2])];
    let normal = to_world(frame, uniform_cone_of(u.0, u.1, caps.f8(|cap| cap.one_minus_cos)));
    Drawn {
        target: caps.v8(|cap| cap.center) + normal * caps.f8(|cap| cap.radius),
        normal,
        error: caps.f8(|cap| cap.error),
        area: caps.f8(|cap| cap.area),
        radiance: caps.v8(|cap| cap.radiance),
    }
}

/// Uniform over each lane's triangle (`sample_area`).
#[inline(always)]
fn draw_on_triangles(triangles: &PerLane<TriangleLight>, u: (F8, F8)) -> Drawn {
    let (b0, b1) = uniform_triangle_of(u.0, u.1);
    let vertex = |k: usize| triangles.v8(|triangle| triangle.vertices[k]);
    let vertices = [vertex(0), vertex(1), vertex(2)];
    Drawn {
        target: triangle_point_of(vertices, b0, b1),
        normal: triangles.v8(|triangle| triangle.normal),
        error: triangles.f8(|triangle| triangle.error),
        area: triangles.f8(|triangle| triangle.area),
        radiance: triangles.v8(|triangle| triangle.radiance),
    }
}

/// Light samples in eight lanes (only lanes of the mask are meaningful).
pub(super) struct LightLanes {
    pub(super) valid: M8,
    pub(super) delta: M8,
    pub(super) wi: V8,
    /// Radiance over pdf (or the delta light's irradiance).
    pub(super) value: V8,
    pub(super) pdf: F8,
    pub(super) origin: V8,
    pub(super) t_max: F8,
}

impl LightLanes {
    /// `LightSource::sample` for each lane's light: caps and triangles in
    /// lanes, other lights through the scalar code.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn sample(
        lights: &LaneLights,
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        point: V8,
        normal: V8,
        error: F8,
        u: (F8, F8),
        hit: &impl Fn(usize) -> SurfaceHit,
    ) -> LightLanes {
        // Which lanes drew a light of each kind (all of them where the
        // scene's lights are all of one kind the lanes sample)
        let lanes_of = |this: bool, other: bool, is: fn(&Option<LaneLight>) -> bool| match (this, other) {
            (false, _) => M8::NONE,
            (true, false) if lights.all_in_lanes => mask,
            _ => M8::from_fn(|i| is(&lights.lights[pick[i]])).and(mask),
        };
        let (has_caps, has_triangles) = (lights.first_cap.is_some(), lights.first_triangle.is_some());
        let cap_lanes = lanes_of(has_caps, has_triangles, |light| matches!(light, Some(LaneLight::Cap(_))));
        let triangle_lanes = lanes_of(has_triangles, has_caps, |light| matches!(light, Some(LaneLight::Triangle(_))));
        let caps = || PerLane::of(lights, pick, lights.first_cap.unwrap_or((CapLight::NONE, true)), LaneLight::cap);
        let triangles = || {
            PerLane::of(lights, pick, lights.first_triangle.unwrap_or((TriangleLight::NONE, true)), LaneLight::triangle)
        };
        let mut out = LightLanes {
            valid: M8::NONE,
            delta: M8::NONE,
            wi: V8::splat(Vec3::Z),
            value: V8::splat(Vec3::ZERO),
            pdf: F8::splat(0.0),
            origin: point,
            t_max: F8::splat(0.0),
        };
        let drawn = match (cap_lanes.any(), triangle_lanes.any()) {
            (true, true) => {
                Some(Drawn::select(cap_lanes, draw_on_caps(&caps(), u), draw_on_triangles(&triangles(), u)))
            }
            (true, false) => Some(draw_on_caps(&caps(), u)),
            (false, true) => Some(draw_on_triangles(&triangles(), u)),
            (false, false) => None,
        };
        let in_lanes = cap_lanes.or(triangle_lanes);
        if let Some(Drawn { target, normal: light_normal, error: light_error, area, radiance }) = drawn {
            let pdf = solid_angle_pdf_of(point, target, light_normal, area);
            // The shadow ray (`SurfaceHit::spawn_ray_to`)
            let (origin, wi, t_max) = ray_to(point, error, normal, target, light_error);
            // Emission is one-sided: the light's front must face the point
            let faces = !light_normal.dot(-wi).le(F8::splat(0.0));
            let valid = in_lanes.and(pdf.gt(F8::splat(0.0))).and(faces);
            out = LightLanes { valid, delta: M8::NONE, wi, value: radiance / pdf, pdf, origin, t_max };
        }
        let others = mask.and_not(in_lanes);
        for lane in (0..LANES).filter(|&i| others.test(i)) {
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
            }
        }
        out
    }
}
