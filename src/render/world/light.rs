//! Light sources as the renderer samples them: delta lights (point, spot,
//! directional) and emissive spheres and triangles (area lights). Each
//! carries the geometry it is sampled on, so sampling needs nothing else.

use glam::{Vec2, Vec3};

use super::sampling::{
    sin_cos_of, uniform_cone, uniform_cone_pdf, uniform_sphere, uniform_sphere_pdf, uniform_triangle,
};
use crate::faults::{self, Fault};
use crate::geometry::real::{Real, V3};
use crate::geometry::{frame_from_z, pow, to_world, Frame, Ray, SurfaceHit, Triangle};
use crate::scene::{Attenuation, Rgb};

/// The part of a sphere that can light the scene: a cap about `frame.z`
/// (from the centre), `one_minus_cos` its 1 − cos θ: 2 for the whole sphere,
/// 0 for none. Light sampling draws only the cap and MIS leaves the rest to
/// BSDF sampling, so there a cap that is too small costs noise, not light;
/// photons leave only from the cap, so it must hold all that can be seen.
#[derive(Clone, Copy, Debug)]
pub struct EmitterCap {
    pub frame: Frame,
    pub one_minus_cos: f32,
    /// The object (an opaque sphere or plane) whose inside the cap was cut
    /// to, if any.
    pub wall: Option<u32>,
}

impl EmitterCap {
    pub const WHOLE: EmitterCap =
        EmitterCap { frame: Frame { x: Vec3::X, y: Vec3::Y, z: Vec3::Z }, one_minus_cos: 2.0, wall: None };

    /// The part of the sphere (`center`, `radius`) inside the sphere
    /// (`other`, `other_radius`): |p − c_o| ≤ R_o on the first sphere ⇔
    /// cos θ ≥ (r² + d² − R_o²)/(2 r d) about the axis toward c_o. In f64:
    /// with smallpt's walls the terms are near 1e10 and differ by 1e8.
    pub fn inside(center: Vec3, radius: f32, other: Vec3, other_radius: f32) -> Self {
        let to_other = other.as_dvec3() - center.as_dvec3();
        let (d, r, big) = (to_other.length(), radius as f64, other_radius as f64);
        let (axis, cos_min) = if d > 0.0 {
            ((to_other / d).as_vec3(), (r * r + d * d - big * big) / (2.0 * r * d))
        } else {
            // Concentric: all inside or nothing
            (Vec3::Z, if r <= big { -1.0 } else { 1.0 })
        };
        let one_minus_cos = (1.0 - cos_min).clamp(0.0, 2.0) as f32;
        if one_minus_cos >= 2.0 {
            return Self::WHOLE;
        }
        EmitterCap { frame: Frame::from_z(axis), one_minus_cos, wall: None }
    }

    /// The part of the sphere (`center`, `radius`) in the half-space
    /// `inward · x > offset`: p = c + r·w there ⇔ inward · w > (offset −
    /// inward · c)/r, a cap about `inward`. In f64, as `inside`.
    pub fn in_half_space(center: Vec3, radius: f32, inward: Vec3, offset: f32) -> Self {
        let inward = inward.as_dvec3().normalize();
        let cos_min = (offset as f64 - inward.dot(center.as_dvec3())) / radius as f64;
        let one_minus_cos = (1.0 - cos_min).clamp(0.0, 2.0) as f32;
        if one_minus_cos >= 2.0 {
            return Self::WHOLE;
        }
        EmitterCap { frame: Frame::from_z(inward.as_vec3()), one_minus_cos, wall: None }
    }

    pub fn is_whole(&self) -> bool {
        self.one_minus_cos >= 2.0
    }

    /// Area of the cap on a sphere of `radius`.
    #[inline]
    pub fn area(&self, radius: f32) -> f32 {
        2.0 * std::f32::consts::PI * radius * radius * self.one_minus_cos
    }
}

/// The surface an area light is sampled on.
#[derive(Clone, Copy, Debug)]
pub enum Emitter {
    /// Sphere `sphere` of the world, emitting from `cap`.
    Sphere { sphere: u32, center: Vec3, radius: f32, cap: EmitterCap },
    /// Triangle `triangle` of the world.
    Triangle { triangle: u32, shape: Triangle },
}

impl Emitter {
    /// The emitting area.
    pub fn area(&self) -> f32 {
        match self {
            Emitter::Sphere { radius, cap, .. } => cap.area(*radius),
            Emitter::Triangle { shape, .. } => shape.area(),
        }
    }

    /// Whether `point` (on the emitter) lies where it emits: on a sphere,
    /// within its cap.
    pub fn emits_at(&self, point: Vec3) -> bool {
        match *self {
            Emitter::Sphere { center, radius, cap, .. } => {
                cap.is_whole() || ((point - center) / radius).dot(cap.frame.z) >= 1.0 - cap.one_minus_cos
            }
            Emitter::Triangle { .. } => true,
        }
    }

    /// Bound on the error of points computed on it.
    #[inline]
    pub fn error(&self) -> f32 {
        match self {
            Emitter::Sphere { center, radius, .. } => crate::geometry::gamma(6) * (center.abs().max_element() + radius),
            Emitter::Triangle { shape, .. } => {
                let [a, b, c] = shape.vertices;
                crate::geometry::gamma(7) * (a.abs() + b.abs() + c.abs()).max_element()
            }
        }
    }
}

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
                let (target, normal, error, pdf) = sample_area(emitter, p, u)?;
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

/// A point on an area light seen from `p`: (point, outward normal, error
/// bound, solid-angle pdf at `p`). Spheres seen from outside are sampled by
/// the cone they subtend (every sample can be visible); triangles by area.
#[inline]
fn sample_area(emitter: &Emitter, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32, f32)> {
    match *emitter {
        Emitter::Sphere { center, radius, cap, .. } => {
            if !cap.is_whole() {
                // Only part of the light can be seen: uniform over that cap
                let normal = cap.frame.to_world(uniform_cone(u, cap.one_minus_cos));
                let point = center + normal * radius;
                let error = emitter.error();
                let pdf = solid_angle_pdf(p, point, normal, cap.area(radius));
                return (pdf > 0.0).then_some((point, normal, error, pdf));
            }
            let to_center = center - p;
            let distance2 = to_center.length_squared();
            let sin2_max = radius * radius / distance2;
            if sin2_max >= 1.0 {
                // Inside the sphere: its outside-facing emission is invisible
                return None;
            }
            let one_minus_cos = sin2_max / (1.0 + (1.0 - sin2_max).sqrt());
            let axis = V3::from(to_center / distance2.sqrt());
            let normal = Vec3::from(sphere_cone_normal_of(axis, sin2_max, one_minus_cos, u.x, u.y));
            Some((center + normal * radius, normal, emitter.error(), uniform_cone_pdf(one_minus_cos)))
        }
        Emitter::Triangle { shape: ref triangle, .. } => {
            let (b0, b1) = uniform_triangle(u);
            let point = triangle_point_of(triangle.vertices.map(V3::from), b0, b1).into();
            let pdf = solid_angle_pdf(p, point, triangle.normal, triangle.area());
            (pdf > 0.0).then_some((point, triangle.normal, emitter.error(), pdf))
        }
    }
}

/// The outward normal of a sphere where a direction drawn uniformly
/// (`u0`, `u1`) in the cone it subtends from a point meets it first, from
/// the angle α that point makes at the centre (pbrt-v4's `Sphere::Sample`),
/// for one draw or several. `axis` is the unit vector from the point toward
/// the centre, `sin2_max` = (radius / distance)², `one_minus_cos_max` the
/// cone's 1 − cos θmax. The direction is never traced to the sphere, so no
/// edge of the cone misses it by rounding, and the point waits on three
/// square roots and divisions one after another where tracing the
/// direction to it waited on five.
#[inline(always)]
pub fn sphere_cone_normal_of<R: Real>(axis: V3<R>, sin2_max: R, one_minus_cos_max: R, u0: R, u1: R) -> V3<R> {
    let (one, zero) = (R::splat(1.0), R::splat(0.0));
    // θ, the direction's angle from the axis, as `uniform_cone_of` draws it
    let one_minus_cos = u0 * one_minus_cos_max;
    let cos_theta = one - one_minus_cos;
    let sin2_theta = (one_minus_cos * (R::splat(2.0) - one_minus_cos)).max(zero);
    // α from the sine rule in the triangle of point, centre and hit
    let cos_alpha = sin2_theta / sin2_max.sqrt() + cos_theta * (one - sin2_theta / sin2_max).max(zero).sqrt();
    let sin_alpha = (one - cos_alpha * cos_alpha).max(zero).sqrt();
    let (sin_phi, cos_phi) = sin_cos_of(u1 * (2.0 * std::f32::consts::PI));
    to_world(frame_from_z(axis), V3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, -cos_alpha))
}

/// The point of barycentrics (b0, b1, 1 − b0 − b1) on a triangle, for one
/// point or several.
#[inline(always)]
pub fn triangle_point_of<R: Real>([a, b, c]: [V3<R>; 3], b0: R, b1: R) -> V3<R> {
    a * b0 + b * b1 + c * (R::splat(1.0) - b0 - b1)
}

/// A uniform-area pdf 1/area turned into solid angle at `p`: d²/(cos θ·A),
/// 0 when the light's front faces away.
#[inline]
fn solid_angle_pdf(p: Vec3, point: Vec3, normal: Vec3, area: f32) -> f32 {
    solid_angle_pdf_of(p.into(), point.into(), normal.into(), area)
}

/// `solid_angle_pdf` for one point or several.
#[inline(always)]
pub fn solid_angle_pdf_of<R: Real>(p: V3<R>, point: V3<R>, normal: V3<R>, area: R) -> R {
    let to_light = point - p;
    let distance2 = to_light.length_squared();
    let cos_light = normal.dot(-to_light) / distance2.sqrt();
    R::select(cos_light.gt(R::splat(0.0)), distance2 / (cos_light * area), R::splat(0.0))
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
        match *emitter {
            Emitter::Sphere { center, radius, cap, .. } => {
                if !cap.is_whole() {
                    // Light sampling reaches only the cap: elsewhere its pdf is 0
                    if !emitter.emits_at(hit.point) {
                        return 0.0;
                    }
                    let normal = (hit.point - center) / radius;
                    return solid_angle_pdf(p, hit.point, normal, cap.area(radius));
                }
                let distance2 = (center - p).length_squared();
                let sin2_max = radius * radius / distance2;
                if sin2_max >= 1.0 {
                    return 0.0;
                }
                uniform_cone_pdf(sin2_max / (1.0 + (1.0 - sin2_max).sqrt()))
            }
            Emitter::Triangle { ref shape, .. } => solid_angle_pdf(p, hit.point, shape.normal, shape.area()),
        }
    }

    /// The emitting sphere's cap, for a light on a sphere.
    pub fn cap(&self) -> Option<EmitterCap> {
        match self {
            LightSource::Area { emitter: Emitter::Sphere { cap, .. }, .. } => Some(*cap),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::rng::Sampler;
    use crate::render::world::World;

    /// The point drawn on a sphere seen from outside is where the cone's
    /// direction, drawn from the same numbers, meets it first: it lies
    /// along the direction and on the side facing the shading point, and
    /// off the cone's edge it is the f64 intersection's. Spheres from 1.02
    /// to 10⁴ radii away (a cone of 79° to one of 10⁻⁴), draws on the
    /// cone's axis and at its very edge among them.
    #[test]
    fn a_sphere_is_met_where_the_cone_direction_meets_it() {
        let mut s = Sampler::new(5, 6, 7);
        let (mut worst_off, mut worst_point) = (0.0f64, 0.0f64);
        for case in 0..20_000 {
            let center = Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 20.0 - 10.0;
            let radius = 0.01 + 2.0 * s.next_f32();
            let distance = radius * (1.02 + 10f32.powf(4.0 * s.next_f32()));
            let p = center + super::uniform_sphere(s.next_2d()) * distance;
            // As `sample_area` draws it
            let to_center = center - p;
            let distance2 = to_center.length_squared();
            let sin2_max = radius * radius / distance2;
            let one_minus_cos = sin2_max / (1.0 + (1.0 - sin2_max).sqrt());
            let axis = to_center / distance2.sqrt();
            let u = match case % 4 {
                0 => Vec2::new(0.0, s.next_f32()),
                1 => Vec2::new(1.0 - f32::EPSILON / 2.0, s.next_f32()),
                _ => s.next_2d(),
            };
            let normal = Vec3::from(sphere_cone_normal_of(V3::from(axis), sin2_max, one_minus_cos, u.x, u.y));
            let direction = Frame::from_z(axis).to_world(uniform_cone(u, one_minus_cos)).as_dvec3().normalize();
            let (p, c, r) = (p.as_dvec3(), center.as_dvec3(), radius as f64);
            let point = c + normal.as_dvec3() * r;
            let to_point = point - p;
            // Along the direction, facing the shading point
            let off = to_point.normalize().cross(direction).length();
            worst_off = worst_off.max(off);
            assert!(off < 2e-5, "case {case}: {off:e} off the direction");
            assert!(normal.as_dvec3().dot(-to_point) > -1e-3 * to_point.length(), "case {case}: faces away");
            // Away from the edge, where the ray meets the sphere steeply, the
            // f64 intersection's near point
            if u.x < 0.5 {
                let b = (p - c).dot(direction);
                let near = -b - (b * b - (p - c).length_squared() + r * r).max(0.0).sqrt();
                // f32's direction is good to ~1e-7: its hit moves by that many
                // distances, a few times over where the ray meets it aslant
                let gap = (p + direction * near - point).length() / (r + 1e-5 * (c - p).length());
                worst_point = worst_point.max(gap);
                assert!(gap < 2e-3, "case {case}: {gap:e} from the intersection");
            }
        }
        eprintln!("worst off {worst_off:e}, worst point {worst_point:e}");
    }

    /// A light sphere sharing its centre with the sphere it is cut to lies
    /// wholly inside a larger one and wholly outside a smaller one, with a
    /// finite frame either way (no direction to the other centre to divide
    /// by). With radii equal it lies on the other, inside by |p − c_o| ≤
    /// R_o: whole, not an empty cap that would leave a light sphere twinned
    /// by an opaque one (a copied object) emitting from nowhere.
    #[test]
    fn a_concentric_cut_is_all_or_nothing() {
        let c = Vec3::new(1.0, -2.0, 3.0);
        assert!(EmitterCap::inside(c, 0.5, c, 2.0).is_whole());
        assert!(EmitterCap::inside(c, 2.0, c, 2.0).is_whole());
        let none = EmitterCap::inside(c, 2.0, c, 0.5);
        assert_eq!(none.one_minus_cos, 0.0);
        assert!(none.frame.z.is_finite() && none.frame.x.is_finite());
        // Off centre, the same formula from both sides: half of a unit
        // sphere lies within √2 of a point at distance 1
        let half = EmitterCap::inside(c, 1.0, c + Vec3::X, 2f32.sqrt());
        assert!((half.one_minus_cos - 1.0).abs() < 1e-6 && (half.frame.z - Vec3::X).length() < 1e-6);
    }

    /// A plane cuts a sphere into the cap past it: about the plane's
    /// inward normal, 1 − cos θ = 1 − (offset − n·c)/r; a sphere wholly
    /// past the plane is whole, one wholly before it is empty.
    #[test]
    fn a_plane_cuts_the_cap_past_it() {
        let c = Vec3::new(0.5, 2.0, -1.0);
        // Inward +y, the plane y = 2.5: the cap above it, cos θ ≥ 0.5
        let cap = EmitterCap::in_half_space(c, 1.0, Vec3::new(0.0, 3.0, 0.0), 2.5);
        assert!(!cap.is_whole());
        assert!((cap.one_minus_cos - 0.5).abs() < 1e-6 && (cap.frame.z - Vec3::Y).length() < 1e-6);
        assert!((cap.area(1.0) - std::f32::consts::PI).abs() < 1e-5);
        // Inward −y through the same plane (y < 2.5): the rest, 1 − cos = 1.5
        let rest = EmitterCap::in_half_space(c, 1.0, -Vec3::Y, -2.5);
        assert!((rest.one_minus_cos - 1.5).abs() < 1e-6 && (rest.frame.z + Vec3::Y).length() < 1e-6);
        assert!(EmitterCap::in_half_space(c, 1.0, Vec3::Y, 0.5).is_whole());
        assert_eq!(EmitterCap::in_half_space(c, 1.0, Vec3::Y, 3.5).one_minus_cos, 0.0);
    }

    /// A sphere emits only from its cap (light samples land nowhere else,
    /// so a hit elsewhere must get no light pdf), and from all of it when
    /// whole; a triangle from all of it.
    #[test]
    fn an_emitter_emits_from_its_cap_only() {
        let (center, radius) = (Vec3::new(0.5, 2.0, -1.0), 2.0);
        let cap = EmitterCap::in_half_space(center, radius, Vec3::Y, 1.0); // y > 1: 1 − cos θ = 1.5
        let sphere = Emitter::Sphere { sphere: 0, center, radius, cap };
        let on = |theta: f32| center + radius * Vec3::new(theta.sin(), theta.cos(), 0.0);
        // cos θ ≥ −0.5: θ up to 120°
        for (degrees, emits) in [(0.0, true), (60.0, true), (115.0, true), (125.0, false), (180.0, false)] {
            assert_eq!(sphere.emits_at(on(f32::to_radians(degrees))), emits, "θ = {degrees}°");
        }
        let whole = Emitter::Sphere { sphere: 0, center, radius, cap: EmitterCap::WHOLE };
        assert!(whole.emits_at(on(std::f32::consts::PI)));
        assert!((sphere.area() - 2.0 * std::f32::consts::PI * 4.0 * 1.5).abs() < 1e-4);
        let shape = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let triangle = Emitter::Triangle { triangle: 0, shape };
        assert!(triangle.emits_at(Vec3::new(0.25, 0.25, 0.0)));
        assert_eq!(triangle.area(), 0.5);
    }

    /// The error bound of an emitter covers how far the points drawn on it
    /// lie from its surface, measured in f64 (and they do stray: the bound
    /// is needed): on smallpt's light, radius 600 with its centre near 700,
    /// whole and cut, a small sphere far from the origin, and a triangle.
    #[test]
    fn emitter_points_lie_within_their_error_bound() {
        use crate::render::world::emission::point_on_emitter;
        let mut sampler = Sampler::new(5, 0, 11);
        let mut check = |emitter: Emitter, distance: &dyn Fn(Vec3) -> f64| {
            let mut worst = 0.0f64;
            for _ in 0..20_000 {
                let (point, _, error) = point_on_emitter(&emitter, sampler.next_2d());
                let off = distance(point);
                assert!(off <= error as f64, "{emitter:?}: {point} lies {off:e} off, bound {error:e}");
                worst = worst.max(off);
            }
            assert!(worst > 0.0, "{emitter:?}: every point exact");
        };
        for (center, radius) in [(Vec3::new(50.0, 681.33, 81.6), 600.0), (Vec3::new(-300.0, 2.0, 1000.0), 0.125)] {
            let cut = EmitterCap::in_half_space(center, radius, Vec3::Y, center.y - 0.5 * radius);
            for cap in [EmitterCap::WHOLE, cut] {
                let sphere = Emitter::Sphere { sphere: 0, center, radius, cap };
                check(sphere, &|p| ((p.as_dvec3() - center.as_dvec3()).length() - radius as f64).abs());
            }
        }
        let [a, b, c] = [Vec3::new(-40.0, 3.0, 7.5), Vec3::new(-39.0, 3.5, 7.0), Vec3::new(-40.5, 4.0, 8.0)];
        let normal = (b - a).as_dvec3().cross((c - a).as_dvec3()).normalize();
        let triangle = Emitter::Triangle { triangle: 0, shape: Triangle::new(a, b, c) };
        check(triangle, &|p| normal.dot(p.as_dvec3() - a.as_dvec3()).abs());
    }

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
        let ceiling = world.spheres.center(5).as_dvec3();
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

    /// Samples on the edge of the cone a sphere light subtends: where the
    /// edge ray misses the sphere by rounding, the sample is the sphere's
    /// point nearest the ray (within rounding of it), its normal is that
    /// point's, and it faces the shaded point like every other sample.
    #[test]
    fn cone_edge_samples_that_miss_by_rounding_take_the_closest_point() {
        let mut s = Sampler::new(0, 0, 306);
        let mut missed = 0;
        for k in 0..20_000 {
            let (center, radius) = (Vec3::new(s.next_f32(), s.next_f32(), s.next_f32()) * 4.0, 0.05 + s.next_f32());
            let p = center
                + crate::render::world::sampling::uniform_sphere(s.next_2d()) * radius * (1.5 + 20.0 * s.next_f32());
            let emitter = Emitter::Sphere { sphere: 0, center, radius, cap: EmitterCap::WHOLE };
            // On the edge, or a hair inside it
            let u = Vec2::new(if k % 2 == 0 { 1.0 } else { 1.0 - f32::EPSILON }, s.next_f32());
            let Some((point, normal, _, pdf)) = sample_area(&emitter, p, u) else { continue };
            assert!(pdf > 0.0 && pdf.is_finite());
            assert!((normal - (point - center) / radius).length() < 1e-4, "normal {normal} at {point}");
            assert!(normal.dot(p - point) > -1e-3 * (p - point).length(), "a sample facing away from {p}");
            // The ray the sample was drawn along, as `sample_area` draws it
            let (to_center, distance2) = (center - p, (center - p).length_squared());
            let sin2_max = radius * radius / distance2;
            let one_minus_cos = sin2_max / (1.0 + (1.0 - sin2_max).sqrt());
            let frame = Frame::from_z(to_center / distance2.sqrt());
            let ray = Ray::new(p, frame.to_world(uniform_cone(u, one_minus_cos)));
            if crate::geometry::intersect_sphere(&ray, center, radius, f32::INFINITY).is_none() {
                missed += 1;
                let along = (point - p).dot(ray.direction);
                assert!((ray.at(along) - point).length() < 1e-4 * (1.0 + (p - center).length()), "{point} off the ray");
            }
        }
        assert!(missed > 0, "no edge ray missed: the fallback was not exercised");
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
