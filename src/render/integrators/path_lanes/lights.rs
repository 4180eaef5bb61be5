//! Light sampling in eight lanes: sphere caps (smallpt's light) computed in
//! the lanes, any other light through the scalar code lane by lane.

use glam::{Vec2, Vec3};

use crate::geometry::{ray_to, to_world, SurfaceHit};
use crate::render::world::lanes::{self, F8, LANES, M8, V8};
use crate::render::world::light::solid_angle_pdf_of;
use crate::render::world::sampling::uniform_cone_of;
use crate::render::world::World;
use crate::scene::Rgb;

/// A sphere light's emitting cap, as light sampling draws it; `None` for
/// lights the scalar code samples lane by lane.
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
    pub(super) const NONE: CapLight = CapLight {
        center: Vec3::ZERO,
        radius: 0.0,
        error: 0.0,
        frame: [Vec3::X, Vec3::Y, Vec3::Z],
        one_minus_cos: 0.0,
        area: 0.0,
        radiance: Vec3::ZERO,
    };
}

/// Sphere-cap lights in eight lanes.
pub(super) struct CapLanes {
    pub(super) center: V8,
    pub(super) radius: F8,
    pub(super) error: F8,
    pub(super) frame: [V8; 3],
    pub(super) one_minus_cos: F8,
    pub(super) area: F8,
    pub(super) radiance: V8,
}

impl CapLanes {
    #[inline(always)]
    fn splat(cap: &CapLight) -> Self {
        CapLanes {
            center: V8::splat(cap.center),
            radius: F8::splat(cap.radius),
            error: F8::splat(cap.error),
            frame: cap.frame.map(V8::splat),
            one_minus_cos: F8::splat(cap.one_minus_cos),
            area: F8::splat(cap.area),
            radiance: V8::splat(cap.radiance),
        }
    }

    #[inline(always)]
    fn gather(caps: [&CapLight; LANES]) -> Self {
        CapLanes {
            center: V8::from_fn(|i| caps[i].center),
            radius: F8::from_fn(|i| caps[i].radius),
            error: F8::from_fn(|i| caps[i].error),
            frame: std::array::from_fn(|k| V8::from_fn(|i| caps[i].frame[k])),
            one_minus_cos: F8::from_fn(|i| caps[i].one_minus_cos),
            area: F8::from_fn(|i| caps[i].area),
            radiance: V8::from_fn(|i| caps[i].radiance),
        }
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
    /// `LightSource::sample` for each lane's light: sphere caps in lanes,
    /// other lights through the scalar code.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn sample(
        caps: &[Option<CapLight>],
        world: &World,
        pick: &[usize; LANES],
        mask: M8,
        point: V8,
        normal: V8,
        error: F8,
        u: (F8, F8),
        hit: &impl Fn(usize) -> SurfaceHit,
    ) -> LightLanes {
        let cap = |i: usize| caps[pick[i]].as_ref();
        let all_caps = caps.iter().all(Option::is_some);
        let cap_lanes = if all_caps { mask } else { M8::from_fn(|i| cap(i).is_some()).and(mask) };
        let mut out = LightLanes {
            valid: M8::NONE,
            delta: M8::NONE,
            wi: V8::splat(Vec3::Z),
            value: V8::splat(Vec3::ZERO),
            pdf: F8::splat(0.0),
            origin: point,
            t_max: F8::splat(0.0),
        };
        if cap_lanes.any() {
            let caps = match caps {
                [Some(only)] => CapLanes::splat(only),
                _ => {
                    // Lanes without a cap compute on the first cap, unused
                    let first = caps.iter().flatten().next().unwrap_or(&CapLight::NONE);
                    CapLanes::gather(lanes::each(|i| cap(i).unwrap_or(first)))
                }
            };
            let CapLanes { center, radius, error: light_error, frame, one_minus_cos, area, radiance } = caps;

            // Uniform over the cap (`sample_area`)
            let light_normal = to_world(frame, uniform_cone_of(u.0, u.1, one_minus_cos));
            let target = center + light_normal * radius;
            let pdf = solid_angle_pdf_of(point, target, light_normal, area);
            // The shadow ray (`SurfaceHit::spawn_ray_to`)
            let (origin, wi, t_max) = ray_to(point, error, normal, target, light_error);
            // Emission is one-sided: the light's front must face the point
            let faces = !light_normal.dot(-wi).le(F8::splat(0.0));
            let valid = cap_lanes.and(pdf.gt(F8::splat(0.0))).and(faces);
            out = LightLanes { valid, delta: M8::NONE, wi, value: radiance / pdf, pdf, origin, t_max };
        }
        let others = if all_caps { M8::NONE } else { mask.and_not(cap_lanes) };
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
