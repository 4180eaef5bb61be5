//! A sphere: its record, the same spheres four to a SIMD group for the
//! hit loops (the cancellation-free form of `geometry::sphere`, written
//! over SIMD lanes: glam's `Vec4` is SSE on x86-64), and a sphere light,
//! which emits from a cap of it (`EmitterCap`) and is sampled by the cone
//! it subtends.

use std::sync::Arc;

use glam::{BVec4A, DVec3, Vec2, Vec3, Vec4};

use super::bvh::Bvh;
use super::{solid_angle_pdf, AreaEmitter};
use crate::geometry::real::{Real, V3};
use crate::geometry::sphere::{nearest_root, sphere_t};
use crate::geometry::{frame_from_z, gamma, to_world, Frame, Ray, SurfaceHit};
use crate::render::world::sampling::{sin_cos_of, uniform_cone, uniform_cone_pdf, uniform_sphere};

/// One sphere of the world.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    /// The object it is the shape of.
    pub object: u32,
}

impl Sphere {
    /// Bound on the error of points computed on it (as `sphere_hit` gives).
    #[inline]
    pub fn error(center: Vec3, radius: f32) -> f32 {
        gamma(6) * (center.abs().max_element() + radius)
    }
}

/// The world's spheres, in order, four to a SIMD group, and in a
/// hierarchy where there are many.
#[derive(Clone, Debug, Default)]
pub struct Spheres {
    pub list: Vec<Sphere>,
    /// The same spheres four to a SIMD group, for the hit loops (empty
    /// where `bvh` holds them).
    pub lanes: SphereLanes,
    /// A hierarchy over them, for a scene of many (`GROUPED_SPHERES`).
    pub bvh: Option<Arc<Bvh>>,
}

/// Up to how many spheres a ray tests them all, four at a time, rather
/// than find them through a hierarchy.
pub const GROUPED_SPHERES: usize = 64;

/// Which spheres a ray meets: all of the world's, or a group's (the
/// spheres that are not walls, for paths held inside them).
#[derive(Clone, Copy, Debug)]
pub enum SphereReach<'w> {
    All(&'w Spheres),
    Groups(&'w SphereLanes),
}

impl SphereReach<'_> {
    /// Nearest hit in (0, t_max): (the world's sphere index, t, near root).
    #[inline]
    pub fn nearest(&self, ray: &Ray, t_max: f32) -> Option<(u32, f32, bool)> {
        let groups = match *self {
            SphereReach::All(Spheres { bvh: Some(bvh), list, .. }) => {
                let hit = |i: u32, best_t| {
                    let sphere = &list[i as usize];
                    sphere_t(ray, sphere.center, sphere.radius, best_t).map(|(t, near)| (t, (t, near)))
                };
                return bvh.nearest(ray, t_max, hit).map(|(i, (t, near))| (i, t, near));
            }
            SphereReach::All(spheres) => &spheres.lanes,
            SphereReach::Groups(groups) => groups,
        };
        let (i, t, near) = groups.nearest(ray, t_max)?;
        Some((groups.id(i), t, near))
    }

    /// Whether any sphere but the world's sphere `except` lies on the ray
    /// in (0, t_max).
    #[inline]
    pub fn any_hit_except(&self, ray: &Ray, t_max: f32, except: Option<u32>) -> bool {
        match *self {
            SphereReach::All(Spheres { bvh: Some(bvh), list, .. }) => bvh.any_hit(ray, t_max, |i| {
                let sphere = &list[i as usize];
                Some(i) != except && sphere_t(ray, sphere.center, sphere.radius, t_max).is_some()
            }),
            SphereReach::All(spheres) => spheres.lanes.any_hit_except(ray, t_max, except),
            SphereReach::Groups(groups) => groups.any_hit_except(ray, t_max, except),
        }
    }

    /// How many spheres it holds.
    pub fn len(&self) -> usize {
        match self {
            SphereReach::All(spheres) => spheres.len(),
            SphereReach::Groups(groups) => groups.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Spheres {
    /// Of `list`, in order.
    pub fn new(list: Vec<Sphere>) -> Self {
        if list.len() > GROUPED_SPHERES {
            let boxes: Vec<(Vec3, Vec3)> = list.iter().map(|s| (s.center - s.radius, s.center + s.radius)).collect();
            return Spheres { bvh: Some(Arc::new(Bvh::new(&boxes, 1))), list, lanes: SphereLanes::default() };
        }
        let centers: Vec<Vec3> = list.iter().map(|s| s.center).collect();
        let radii: Vec<f32> = list.iter().map(|s| s.radius).collect();
        let lanes = SphereLanes::new(&centers, &radii, (0..list.len() as u32).collect());
        Spheres { list, lanes, bvh: None }
    }

    #[inline]
    pub fn center(&self, i: usize) -> Vec3 {
        self.list[i].center
    }

    #[inline]
    pub fn radius(&self, i: usize) -> f32 {
        self.list[i].radius
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

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

/// A sphere light: the sphere and the cap it emits from.
#[derive(Clone, Copy, Debug)]
pub struct CappedSphere {
    pub center: Vec3,
    pub radius: f32,
    pub cap: EmitterCap,
}

impl AreaEmitter for CappedSphere {
    fn area(&self) -> f32 {
        self.cap.area(self.radius)
    }

    fn emits_at(&self, point: Vec3) -> bool {
        let cap = &self.cap;
        cap.is_whole() || ((point - self.center) / self.radius).dot(cap.frame.z) >= 1.0 - cap.one_minus_cos
    }

    #[inline]
    fn error(&self) -> f32 {
        Sphere::error(self.center, self.radius)
    }

    fn uniform_point(&self, u: Vec2) -> (Vec3, Vec3) {
        let cap = &self.cap;
        // Uniform over the emitting cap (the whole sphere when 1 − cos = 2)
        let normal =
            if cap.is_whole() { uniform_sphere(u) } else { cap.frame.to_world(uniform_cone(u, cap.one_minus_cos)) };
        (self.center + normal * self.radius, normal)
    }

    /// Seen from outside, by the cone it subtends (every sample can be
    /// visible); uniform over the cap where only a cap emits.
    #[inline]
    fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(Vec3, Vec3, f32)> {
        let CappedSphere { center, radius, cap } = *self;
        if !cap.is_whole() {
            // Only part of the light can be seen: uniform over that cap
            let normal = cap.frame.to_world(uniform_cone(u, cap.one_minus_cos));
            let point = center + normal * radius;
            let pdf = solid_angle_pdf(p, point, normal, cap.area(radius));
            return (pdf > 0.0).then_some((point, normal, pdf));
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
        Some((center + normal * radius, normal, uniform_cone_pdf(one_minus_cos)))
    }

    #[inline]
    fn pdf_from(&self, p: Vec3, hit: &SurfaceHit) -> f32 {
        let CappedSphere { center, radius, cap } = *self;
        if !cap.is_whole() {
            // Light sampling reaches only the cap: elsewhere its pdf is 0
            if !self.emits_at(hit.point) {
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

    fn held_by(&self, holds: &dyn Fn(DVec3, f64) -> bool) -> bool {
        let (c, r) = (self.center.as_dvec3(), self.radius as f64);
        let cos_min = 1.0 - self.cap.one_minus_cos as f64;
        if cos_min > 0.0 {
            // The ball on the cap's rim circle holds the cap
            let rim_center = c + self.cap.frame.z.as_dvec3() * (r * cos_min);
            holds(rim_center, r * (1.0 - cos_min * cos_min).sqrt() * (1.0 + 1e-6))
        } else {
            holds(c, r)
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

/// Lanes with no sphere: a centre at infinity gives NaN, and every
/// comparison with NaN fails, so they never hit.
const EMPTY: f32 = f32::INFINITY;

#[derive(Clone, Debug, Default)]
pub struct SphereLanes {
    center_x: Vec<Vec4>,
    center_y: Vec<Vec4>,
    center_z: Vec<Vec4>,
    radius2: Vec<Vec4>,
    /// Which sphere of the world each lane holds, in order.
    ids: Vec<u32>,
}

impl SphereLanes {
    /// Spheres `ids` of the world, with these centres and radii.
    pub fn new(centers: &[Vec3], radii: &[f32], ids: Vec<u32>) -> Self {
        let groups = centers.len().div_ceil(4);
        let lane = |i: usize, f: &dyn Fn(usize) -> f32| {
            Vec4::from_array([0, 1, 2, 3].map(|k| if i * 4 + k < centers.len() { f(i * 4 + k) } else { EMPTY }))
        };
        Self {
            center_x: (0..groups).map(|i| lane(i, &|j| centers[j].x)).collect(),
            center_y: (0..groups).map(|i| lane(i, &|j| centers[j].y)).collect(),
            center_z: (0..groups).map(|i| lane(i, &|j| centers[j].z)).collect(),
            radius2: (0..groups).map(|i| lane(i, &|j| radii[j] * radii[j])).collect(),
            ids,
        }
    }

    /// The world's index of the sphere in lane `i`.
    #[inline]
    pub fn id(&self, i: usize) -> u32 {
        self.ids[i]
    }

    pub fn len(&self) -> usize {
        self.ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Per lane of one group: the nearest root in (0, t_max), infinity where
    /// there is none, and whether it is the near root.
    #[inline(always)]
    fn group(cx: Vec4, cy: Vec4, cz: Vec4, r2: Vec4, ray: &Ray, t_max: Vec4) -> (Vec4, BVec4A) {
        let (o, d) = (ray.origin, ray.direction);
        let f = V3::new(Vec4::splat(o.x) - cx, Vec4::splat(o.y) - cy, Vec4::splat(o.z) - cz);
        let (t, hit, near) = nearest_root(f, V3::splat(d), r2, t_max);
        (Vec4::select(hit, t, Vec4::INFINITY), hit & near)
    }

    /// The groups' lanes side by side (zipped: no bounds checks in the loop).
    #[inline(always)]
    fn groups(&self) -> impl Iterator<Item = (Vec4, Vec4, Vec4, Vec4)> + '_ {
        self.center_x
            .iter()
            .zip(&self.center_y)
            .zip(&self.center_z)
            .zip(&self.radius2)
            .map(|(((x, y), z), r)| (*x, *y, *z, *r))
    }

    /// Nearest hit in (0, t_max): (sphere index, t, near root).
    #[inline]
    pub fn nearest(&self, ray: &Ray, t_max: f32) -> Option<(usize, f32, bool)> {
        let mut best = t_max;
        let mut found = None;
        for (g, (cx, cy, cz, r2)) in self.groups().enumerate() {
            let (t, near) = Self::group(cx, cy, cz, r2, ray, Vec4::splat(best));
            let closest = t.min_element();
            if closest < best {
                // The lane holding the minimum, without a loop over lanes
                let lane = t.cmpeq(Vec4::splat(closest)).bitmask().trailing_zeros() as usize;
                best = closest;
                found = Some((g * 4 + lane, closest, near.bitmask() & (1 << lane) != 0));
            }
        }
        found
    }

    /// Whether any sphere lies on the ray in (0, t_max).
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        let limit = Vec4::splat(t_max);
        self.groups().any(|(cx, cy, cz, r2)| Self::group(cx, cy, cz, r2, ray, limit).0.cmplt(limit).any())
    }

    /// `any_hit` but for the world's sphere `except`.
    #[inline]
    pub fn any_hit_except(&self, ray: &Ray, t_max: f32, except: Option<u32>) -> bool {
        let Some(skip) = except.and_then(|id| self.ids.iter().position(|&i| i == id)) else {
            return self.any_hit(ray, t_max);
        };
        let limit = Vec4::splat(t_max);
        self.groups().enumerate().any(|(g, (cx, cy, cz, r2))| {
            let hits = Self::group(cx, cy, cz, r2, ray, limit).0.cmplt(limit).bitmask();
            let skipped = if skip / 4 == g { 1 << (skip % 4) } else { 0 };
            hits & !skipped != 0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::world::rng::Sampler;

    /// Four-wide lanes agree with the scalar test, sphere by sphere.
    #[test]
    fn lanes_match_the_scalar_intersection() {
        let mut s = Sampler::new(0, 0, 99);
        for count in [1usize, 3, 4, 5, 9, 13] {
            let centers: Vec<Vec3> = (0..count).map(|_| uniform_sphere(s.next_2d()) * 5.0).collect();
            let radii: Vec<f32> = (0..count).map(|_| 0.2 + s.next_f32()).collect();
            let lanes = SphereLanes::new(&centers, &radii, (0..count as u32).collect());
            for _ in 0..2000 {
                let ray = Ray::new(uniform_sphere(s.next_2d()) * 8.0 * s.next_f32(), uniform_sphere(s.next_2d()));
                let t_max = if s.next_f32() < 0.3 { 4.0 } else { f32::INFINITY };
                let mut expected: Option<(usize, f32, bool)> = None;
                for i in 0..count {
                    if let Some((t, near)) = sphere_t(&ray, centers[i], radii[i], expected.map_or(t_max, |e| e.1)) {
                        expected = Some((i, t, near));
                    }
                }
                assert_eq!(lanes.nearest(&ray, t_max), expected);
                assert_eq!(lanes.any_hit(&ray, t_max), expected.is_some());
                // Without one sphere: whether any other lies on the ray
                let except = s.next_u64() as usize % count;
                let others = (0..count).any(|i| i != except && sphere_t(&ray, centers[i], radii[i], t_max).is_some());
                assert_eq!(lanes.any_hit_except(&ray, t_max, Some(except as u32)), others);
            }
        }
    }

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
            let p = center + uniform_sphere(s.next_2d()) * distance;
            // As `sample_from` draws it
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
            let p = center + uniform_sphere(s.next_2d()) * radius * (1.5 + 20.0 * s.next_f32());
            let emitter = CappedSphere { center, radius, cap: EmitterCap::WHOLE };
            // On the edge, or a hair inside it
            let u = Vec2::new(if k % 2 == 0 { 1.0 } else { 1.0 - f32::EPSILON }, s.next_f32());
            let Some((point, normal, pdf)) = emitter.sample_from(p, u) else { continue };
            assert!(pdf > 0.0 && pdf.is_finite());
            assert!((normal - (point - center) / radius).length() < 1e-4, "normal {normal} at {point}");
            assert!(normal.dot(p - point) > -1e-3 * (p - point).length(), "a sample facing away from {p}");
            // The ray the sample was drawn along, as `sample_from` draws it
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

    /// Past `GROUPED_SPHERES` the spheres are found through a hierarchy:
    /// the same nearest sphere, t and root as testing every one in order
    /// (`sphere_t`), and any hit, with or without one sphere, exactly where
    /// there is one.
    #[test]
    fn many_spheres_are_found_as_testing_each_finds_them() {
        let mut s = Sampler::new(0, 0, 55);
        let list: Vec<Sphere> = (0..500)
            .map(|object| {
                let center = uniform_sphere(s.next_2d()) * 6.0 * s.next_f32();
                Sphere { center, radius: 0.05 + 0.4 * s.next_f32(), object }
            })
            .collect();
        let spheres = Spheres::new(list.clone());
        assert!(spheres.bvh.is_some() && spheres.lanes.is_empty());
        let reach = SphereReach::All(&spheres);
        let (mut hits, mut misses) = (0, 0);
        for k in 0..4000 {
            let origin = uniform_sphere(s.next_2d()) * 9.0 * s.next_f32();
            let direction = match k % 2 {
                0 => (list[k % list.len()].center - origin).normalize(),
                _ => uniform_sphere(s.next_2d()),
            };
            let ray = Ray::new(origin, direction);
            let t_max = if k % 3 == 0 { 3.0 } else { f32::INFINITY };
            let mut expected: Option<(u32, f32, bool)> = None;
            for (i, sphere) in list.iter().enumerate() {
                let best = expected.map_or(t_max, |e| e.1);
                if let Some((t, near)) = sphere_t(&ray, sphere.center, sphere.radius, best) {
                    expected = Some((i as u32, t, near));
                }
            }
            assert_eq!(reach.nearest(&ray, t_max), expected, "ray {ray:?}");
            let except = (k % list.len()) as u32;
            let others = (list.iter().enumerate())
                .any(|(i, o)| i as u32 != except && sphere_t(&ray, o.center, o.radius, t_max).is_some());
            assert_eq!(reach.any_hit_except(&ray, t_max, Some(except)), others);
            assert_eq!(reach.any_hit_except(&ray, t_max, None), expected.is_some());
            (hits, misses) = (hits + expected.is_some() as u32, misses + expected.is_none() as u32);
        }
        assert!(hits > 1500 && misses > 500, "{hits} hits, {misses} misses");
    }
}
