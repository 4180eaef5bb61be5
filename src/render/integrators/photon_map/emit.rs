//! Where photons come from: every enabled light emits in proportion to its
//! power (`LightSource::emit`: point lights uniformly over the sphere, spot
//! lights within their cone weighted by the falloff, infinite lights from a
//! disc covering the scene, area lights from their surface with
//! cosine-weighted directions); caustic photons aim at specular objects.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::geometry::{Frame, Ray};
use crate::render::world::light::Aim;
use crate::render::world::rng::Sampler;
use crate::render::world::sampling::{concentric_disk, uniform_cone, uniform_cone_pdf};
use crate::render::world::shapes::bvh::Bvh;
use crate::render::world::World;
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

/// The targets of caustic photons: the specular objects' bounding spheres
/// (Jensen's projection maps, in their simplest form), and over many of
/// them a hierarchy, so that a photon's density, summed over every target
/// its line passes, costs the targets near the line rather than all.
#[derive(Clone, Debug, Default)]
pub struct SpecularTargets {
    pub list: Vec<(Vec3, f32)>,
    tree: Option<Bvh>,
    /// A ball about every target's box: (centre, radius).
    ball: (Vec3, f32),
}

/// From how many targets their hierarchy finds those on a line.
const TARGET_TREE: usize = 16;

/// How much wider a target's box is than its sphere: a direction the
/// cone test takes by rounding, a hair outside the sphere, stays inside.
const TARGET_SLACK: f32 = 1e-3;

impl SpecularTargets {
    pub fn of(world: &World) -> Self {
        Self::new(specular_targets(world))
    }

    fn new(list: Vec<(Vec3, f32)>) -> Self {
        let boxes: Vec<(Vec3, Vec3)> = (list.iter())
            .map(|&(center, radius)| {
                let reach = radius * (1.0 + TARGET_SLACK) + center.abs().max_element() * TARGET_SLACK;
                (center - reach, center + reach)
            })
            .collect();
        let tree = (list.len() > TARGET_TREE).then(|| Bvh::new(&boxes, 1));
        let (lo, hi) =
            boxes.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
        let ball = if lo.x <= hi.x { ((lo + hi) * 0.5, (hi - lo).length() * 0.5) } else { (Vec3::ZERO, 0.0) };
        SpecularTargets { list, tree, ball }
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Each target the ray from `origin` along `direction` may pass (all of
    /// them, or those whose boxes it enters), in the list's order: a sum
    /// over them adds what a sum over the whole list adds, in the same order.
    #[inline]
    fn on_ray(&self, origin: Vec3, direction: Vec3, mut visit: impl FnMut(&(Vec3, f32))) {
        let Some(tree) = &self.tree else {
            return self.list.iter().for_each(visit);
        };
        let mut found = Vec::new();
        tree.any_hit(&Ray::new(origin, direction), f32::INFINITY, |i| {
            found.push(i);
            false
        });
        found.sort_unstable();
        found.iter().for_each(|&i| visit(&self.list[i as usize]));
    }

    /// `on_ray` for the whole line through `point` along `direction`: the
    /// ray started behind every target.
    #[inline]
    fn on_line(&self, point: Vec3, direction: Vec3, visit: impl FnMut(&(Vec3, f32))) {
        let back = (point - self.ball.0).length() + self.ball.1;
        self.on_ray(point - direction * back, direction, visit)
    }
}

/// Bounding spheres of the specular objects.
fn specular_targets(world: &World) -> Vec<(Vec3, f32)> {
    world
        .objects
        .iter()
        .filter(|o| crate::render::world::materials::Bsdf::new(&world.materials[o.material as usize]).is_specular())
        .filter(|o| !matches!(world.materials[o.material as usize], crate::scene::MaterialModel::Emissive { .. }))
        .filter_map(|o| world.shapes.bounding_ball(o.shape))
        .collect()
}

/// Emit a photon aimed at one of the specular `targets`: a direction within
/// the cone a target's bounding sphere subtends from the emission point.
/// Its power divides by the pdf summed over every cone containing the
/// direction, so overlapping targets are not counted twice.
pub fn emit_toward(
    world: &World,
    picker: &LightPicker,
    targets: &SpecularTargets,
    sampler: &mut Sampler,
) -> Option<EmittedPhoton> {
    if targets.is_empty() {
        return None;
    }
    let (index, pick) = picker.pick(sampler.next_f32())?;
    let light = &world.lights[index];
    let count = targets.list.len();
    let target = targets.list[((sampler.next_f32() * count as f32) as usize).min(count - 1)];
    let (u1, u2) = (sampler.next_2d(), sampler.next_2d());
    let aim = Targets { targets, target, target_pick: 1.0 / count as f32, u1, u2, scene_radius: world.bounds_radius };
    let (ray, power) = light.emit_toward(&aim, u1, u2)?;
    power.is_finite().then_some(EmittedPhoton { ray, power: power / pick })
}

/// Caustic photons' aim: a target drawn among `targets` (bounding
/// spheres), and the density of a direction or a start over all of them.
struct Targets<'t> {
    targets: &'t SpecularTargets,
    /// The target drawn, with probability `target_pick`.
    target: (Vec3, f32),
    target_pick: f32,
    /// `u1` places a start on a target's disc, `u2` a direction in its cone.
    u1: Vec2,
    u2: Vec2,
    /// How far upstream light from infinitely far starts.
    scene_radius: f32,
}

impl Aim for Targets<'_> {
    /// Within the cone the drawn target subtends from `origin`.
    fn direction_from(&self, origin: Vec3) -> Option<Vec3> {
        let to = self.target.0 - origin;
        let distance2 = to.length_squared();
        let sin2 = self.target.1 * self.target.1 / distance2;
        if sin2 >= 1.0 {
            return None;
        }
        let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
        Some(Frame::from_z(to / distance2.sqrt()).to_world(uniform_cone(self.u2, one_minus_cos)))
    }

    /// Over every target whose cone holds `direction`, so overlapping
    /// targets are not counted twice.
    fn direction_pdf(&self, origin: Vec3, direction: Vec3) -> f32 {
        let mut pdf = 0.0;
        self.targets.on_ray(origin, direction, |(center, radius)| {
            let to = *center - origin;
            let distance2 = to.length_squared();
            let sin2 = radius * radius / distance2;
            if sin2 >= 1.0 {
                return;
            }
            let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
            let cos = to.dot(direction) / distance2.sqrt();
            if cos >= 1.0 - one_minus_cos {
                pdf += uniform_cone_pdf(one_minus_cos) * self.target_pick;
            }
        });
        pdf
    }

    /// On a disc just covering the drawn target across `direction`,
    /// upstream of the scene; the density of starts over every target's
    /// disc that holds the line.
    fn upstream(&self, direction: Vec3) -> (Vec3, f32) {
        let (center, radius) = self.target;
        let frame = Frame::from_z(direction);
        let disc = concentric_disk(self.u1) * radius;
        let origin = center - direction * (2.0 * self.scene_radius.max(radius)) + frame.x * disc.x + frame.y * disc.y;
        let mut density = 0.0;
        self.targets.on_line(origin, direction, |(c, r)| {
            let offset = *c - origin;
            if (offset - direction * offset.dot(direction)).length_squared() <= r * r {
                density += self.target_pick / (PI * r * r);
            }
        });
        (origin, density)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{presets, Attenuation, Light, LightKind, MaterialModel, Object, Scene, Shape, ValidScene};

    /// smallpt's room and balls without its light.
    fn dark_smallpt() -> Scene {
        let mut scene = presets::preset("smallpt").and_then(Result::ok).expect("smallpt").into_scene();
        scene.objects.retain(|o| o.name != "light");
        scene
    }

    fn light(kind: LightKind, color: Rgb, intensity: f32) -> Light {
        let name = format!("test {} {color}", kind.kind_name());
        Light { name, kind, color, intensity, attenuation: Attenuation::default(), enabled: true }
    }

    fn world(scene: Scene) -> World {
        World::new(&ValidScene::new(scene).expect("a valid scene"))
    }

    /// Lights are picked by their power's luminance (Rec. 709), a dark one
    /// never, and no index past them is.
    #[test]
    fn lights_are_picked_by_their_powers_luminance() {
        let mut scene = dark_smallpt();
        let at = LightKind::Point { position: Vec3::new(50.0, 60.0, 80.0) };
        scene.lights =
            vec![light(at.clone(), Rgb::X, 2.0), light(at.clone(), Rgb::Z, 0.0), light(at.clone(), Rgb::Y, 1.0)];
        let picker = LightPicker::new(&world(scene));
        let red = 0.2126 * 2.0 / (0.2126 * 2.0 + 0.7152);
        let p = [0, 1, 2, 3].map(|i| picker.probability(i));
        assert!((p[0] - red).abs() < 1e-6 && (p[2] - (1.0 - red)).abs() < 1e-6 && p[1] == 0.0 && p[3] == 0.0, "{p:?}");
        let (below, above) = (picker.pick(red * 0.999).unwrap(), picker.pick(red * 1.001).unwrap());
        assert_eq!((below.0, above.0), (0, 2));
        assert!((below.1 - p[0]).abs() < 1e-6 && (above.1 - p[2]).abs() < 1e-6);
        assert_eq!(picker.pick(0.999_999).map(|(i, _)| i), Some(2));
        // u = 1, past what a sampler draws: still a light, never a dark one
        assert_eq!(picker.pick(1.0).map(|(i, _)| i), Some(2));
        let mut dark_last = dark_smallpt();
        dark_last.lights = vec![light(at.clone(), Rgb::X, 2.0), light(at.clone(), Rgb::Z, 0.0)];
        assert!(LightPicker::new(&world(dark_last)).pick(1.0).is_none_or(|(_, p)| p > 0.0));
        assert!(!picker.is_empty() && LightPicker::new(&world(dark_smallpt())).is_empty());
    }

    /// A photon from a point light leaves it carrying the light's power,
    /// 4π I, over the chance of picking the light.
    #[test]
    fn a_photon_carries_its_lights_power_over_its_pick() {
        let mut scene = dark_smallpt();
        let position = Vec3::new(50.0, 60.0, 80.0);
        let color = Rgb::new(1.0, 0.5, 0.25);
        scene.lights = vec![light(LightKind::Point { position }, color, 3.0)];
        let alone = world(scene.clone());
        let twin =
            Light { name: "twin".into(), ..light(LightKind::Point { position: position + Vec3::X }, color, 3.0) };
        scene.lights.push(twin);
        let world = world(scene);
        let picker = LightPicker::new(&world);
        let mut s = Sampler::new(0, 0, 1);
        for _ in 0..100 {
            let photon = emit(&world, &picker, &mut s).expect("a photon");
            let expected = color * (3.0 * 4.0 * PI * 2.0);
            assert!((photon.power - expected).abs().max_element() < 1e-5 * expected.max_element(), "{}", photon.power);
            assert!(photon.ray.origin.distance(position) < 1.5 && (photon.ray.direction.length() - 1.0).abs() < 1e-5);
        }
        // A caustic photon too: the same draws from the first twin carry
        // twice what they carry from it alone
        let (targets, alone_picker) = (SpecularTargets::of(&world), LightPicker::new(&alone));
        let mut twins = 0;
        for i in 0..100 {
            let (mut s, mut same) = (Sampler::new(i, 0, 2), Sampler::new(i, 0, 2));
            let Some(photon) = emit_toward(&world, &picker, &targets, &mut s) else { continue };
            if photon.ray.origin == position {
                twins += 1;
                let single = emit_toward(&alone, &alone_picker, &targets, &mut same).expect("the same photon");
                assert_eq!(photon.power, single.power * 2.0);
            }
        }
        assert!(twins > 20, "{twins} photons from the first twin");
    }

    /// The caustic map's targets: bounding spheres of the mirror and glass
    /// objects (a triangle's about its centroid, a hair larger, whichever
    /// corner is farthest), not of planes, emitters or diffuse objects.
    #[test]
    fn specular_targets_bound_the_mirrors_and_the_glass() {
        let (a, b, c) = (Vec3::new(10.0, 10.0, 10.0), Vec3::new(16.0, 10.0, 10.0), Vec3::new(10.0, 19.0, 10.0));
        let centroid = (a + b + c) / 3.0;
        for [a, b, c] in [[a, b, c], [c, a, b], [b, c, a]] {
            let mut scene = presets::preset("smallpt").and_then(Result::ok).expect("smallpt").into_scene();
            let plane = Shape::Plane { point: Vec3::new(0.0, 80.0, 0.0), normal: -Vec3::Y };
            let triangle = Shape::Triangle { a, b, c };
            scene.objects.push(Object { name: "glass triangle".into(), shape: triangle, material: "glass".into() });
            scene.objects.push(Object { name: "mirror plane".into(), shape: plane, material: "mirror".into() });
            let targets = specular_targets(&world(scene));
            let expected = [
                (Vec3::new(27.0, 16.5, 47.0), 16.5),
                (Vec3::new(73.0, 16.5, 78.0), 16.5),
                (centroid, (Vec3::new(10.0, 19.0, 10.0) - centroid).length() * 1.001),
            ];
            assert_eq!(targets.len(), 3, "{targets:?}");
            for ((center, radius), (c, r)) in targets.iter().zip(expected) {
                assert!(center.distance(c) < 1e-4 && (radius - r).abs() < 1e-4, "{targets:?}");
            }
        }
    }

    /// Caustic photons of every kind of light, against the densities
    /// written out in f64: each aims into a target's cone (or, from
    /// afar, through its disc) and carries the light's output that way over
    /// the density summed over every target that way.
    #[test]
    fn caustic_photons_aim_at_the_targets_with_their_share_of_power() {
        let lamp_center = Vec3::new(50.0, 60.0, 81.6);
        let (intensity, radiance, sky) = (3.0f32, 12.0f32, 0.5f32);
        let down = Vec3::new(0.2, -1.0, 0.1).normalize();
        let aim = (Vec3::new(27.0, 16.5, 47.0) - lamp_center).normalize();
        let spot =
            LightKind::Spot { position: lamp_center, direction: aim, cone_angle_degrees: 40.0, falloff_exponent: 2.0 };
        let cases: [(&str, Option<LightKind>); 5] = [
            ("point", Some(LightKind::Point { position: lamp_center })),
            ("spot", Some(spot)),
            ("directional", Some(LightKind::Directional { direction: down })),
            ("area", None),
            ("background", None),
        ];
        for (name, kind) in cases {
            let mut scene = dark_smallpt();
            // A third ball whose cone, seen from the lamp, overlaps the mirror ball's
            let shape = Shape::Sphere { center: Vec3::new(40.0, 20.0, 50.0), radius: 8.0 };
            scene.objects.push(Object { name: "small ball".into(), shape, material: "glass".into() });
            match (name, kind) {
                (_, Some(kind)) => scene.lights.push(light(kind, Rgb::ONE, intensity)),
                ("area", None) => {
                    let shape = Shape::Sphere { center: lamp_center, radius: 5.0 };
                    scene.objects.push(Object { name: "lamp".into(), shape, material: "light".into() });
                    assert!(matches!(
                        scene.materials.iter().find(|m| m.name == "light").unwrap().model,
                        MaterialModel::Emissive { .. }
                    ));
                }
                _ => scene.background = Rgb::splat(sky),
            }
            let world = world(scene);
            let (picker, targets) = (LightPicker::new(&world), SpecularTargets::of(&world));
            assert_eq!((world.lights.len(), targets.list.len()), (1, 3), "{name}");
            let share = 1.0 / targets.list.len() as f64;
            // Solid-angle density of aiming `d` from `o`, and area density
            // of a line along `d` through `o` crossing the targets' discs
            let cones = |o: Vec3, d: Vec3| -> (f64, bool, usize) {
                let (mut sum, mut on_edge, mut within) = (0.0, false, 0);
                for (c, r) in &targets.list {
                    let to = (*c - o).as_dvec3();
                    let cos_max = (1.0 - (*r as f64 / to.length()).powi(2)).sqrt();
                    let cos = to.normalize().dot(d.as_dvec3());
                    on_edge |= (cos - cos_max).abs() < 1e-5;
                    if cos >= cos_max {
                        sum += share / (2.0 * std::f64::consts::PI * (1.0 - cos_max));
                        within += 1;
                    }
                }
                (sum, on_edge, within)
            };
            let discs = |o: Vec3, d: Vec3| -> (f64, bool, usize) {
                let (mut sum, mut on_edge, mut within) = (0.0, false, 0);
                for (c, r) in &targets.list {
                    let to = (*c - o).as_dvec3();
                    let off_axis = (to - d.as_dvec3() * to.dot(d.as_dvec3())).length();
                    on_edge |= (off_axis / *r as f64 - 1.0).abs() < 1e-4;
                    if off_axis <= *r as f64 {
                        sum += share / (std::f64::consts::PI * (*r as f64).powi(2));
                        within += 1;
                    }
                }
                (sum, on_edge, within)
            };
            let mut s = Sampler::new(0, 0, 2);
            let (mut emitted, mut overlapped) = (0, 0);
            for _ in 0..4000 {
                let Some(photon) = emit_toward(&world, &picker, &targets, &mut s) else { continue };
                emitted += 1;
                let (o, d) = (photon.ray.origin, photon.ray.direction);
                let ((density, on_edge, within), output) = match name {
                    "point" => (cones(o, d), intensity as f64),
                    "spot" => (cones(o, d), (intensity * d.dot(aim).powf(2.0)) as f64),
                    "directional" => (discs(o, d), intensity as f64),
                    "background" => {
                        let (density, on_edge, within) = discs(o, d);
                        ((density / (4.0 * std::f64::consts::PI), on_edge, within), sky as f64)
                    }
                    _ => {
                        let normal = (o - lamp_center).normalize();
                        let area = 4.0 * std::f64::consts::PI * 25.0;
                        (cones(o, d), radiance as f64 * normal.dot(d) as f64 * area)
                    }
                };
                if on_edge {
                    continue;
                }
                assert!(density > 0.0, "{name}: a photon from {o} along {d} misses every target");
                overlapped += (within > 1) as usize;
                let expected = output / density;
                let got = photon.power.x as f64;
                assert!((got / expected - 1.0).abs() < 1e-3, "{name}: power {got}, expected {expected}");
                if name == "directional" {
                    assert_eq!(d, down);
                }
            }
            // Where two targets overlap, a photon's density is both's
            assert!(emitted > 1000 && overlapped > 50, "{name}: {emitted} photons, {overlapped} through two targets");
        }
    }

    /// Toward one target, photons fill its cone or its disc evenly: from a
    /// point light, unit directions within the cone with E[1 − cos] half
    /// the cone's 1 − cos θmax (uniform in solid angle); from afar (a
    /// directional light, the sky), lines starting upstream, outside the
    /// scene's bounds, whose offsets from the target's centre are uniform on
    /// its disc, E[offset²] = r²/2. Means within 5 standard errors.
    #[test]
    fn photons_fill_a_single_targets_cone_and_disc() {
        let lamp = Vec3::new(50.0, 60.0, 81.6);
        let down = Vec3::new(0.2, -1.0, 0.1).normalize();
        let cases = [
            ("point", Some(LightKind::Point { position: lamp })),
            ("directional", Some(LightKind::Directional { direction: down })),
            ("background", None),
        ];
        for (name, kind) in cases {
            let mut scene = dark_smallpt();
            // The glass ball made diffuse: the mirror ball is the one target
            let glass = scene.objects.iter_mut().find(|o| o.material == "glass").expect("smallpt's glass ball");
            glass.material = "grey".into();
            match kind {
                Some(kind) => scene.lights.push(light(kind, Rgb::ONE, 1.0)),
                None => scene.background = Rgb::ONE,
            }
            let world = world(scene);
            let (picker, targets) = (LightPicker::new(&world), SpecularTargets::of(&world));
            let [(center, radius)] = targets.list[..] else { panic!("{targets:?}") };
            let mut s = Sampler::new(0, 0, 3);
            // A line grazing the disc's rim can be lost to rounding (no density, no photon)
            let samples: Vec<f64> = (0..20_000)
                .filter_map(|_| emit_toward(&world, &picker, &targets, &mut s))
                .map(|photon| {
                    let (o, d) = (photon.ray.origin, photon.ray.direction);
                    assert!((d.length() - 1.0).abs() < 1e-5, "{name}: direction {d}");
                    let to = center - o;
                    if name == "point" {
                        let one_minus_cos_max = 1.0 - (1.0 - (radius / to.length()).powi(2)).sqrt();
                        let one_minus_cos = 1.0 - to.normalize().dot(d);
                        assert!(one_minus_cos <= one_minus_cos_max * 1.001, "{name}: outside the cone");
                        (one_minus_cos / one_minus_cos_max) as f64
                    } else {
                        let offset = (to - d * to.dot(d)).length();
                        let upstream = to.dot(d) > 0.0 && o.distance(world.bounds_center) >= world.bounds_radius;
                        assert!(upstream && offset <= radius * 1.001, "{name}: from {o} along {d}");
                        ((offset / radius) as f64).powi(2)
                    }
                })
                .collect();
            assert!(samples.len() > 19_900, "{name}: {} photons of 20 000", samples.len());
            // Both fractions are uniform on [0, 1] when the photons are even
            let n = samples.len() as f64;
            let mean = samples.iter().sum::<f64>() / n;
            let standard_error = (samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
            assert!((mean - 0.5).abs() < 5.0 * standard_error, "{name}: mean {mean} ± {standard_error}");
        }
    }

    /// Over many targets, the hierarchy finds every target a photon's ray
    /// or line passes: the densities equal the sums over the whole list,
    /// bit for bit, for photons aimed at the targets and for any other.
    #[test]
    fn many_targets_give_the_densities_of_all_of_them() {
        use crate::render::world::sampling::uniform_sphere;
        let mut s = Sampler::new(0, 0, 71);
        let list: Vec<(Vec3, f32)> =
            (0..300).map(|_| (uniform_sphere(s.next_2d()) * 6.0 * s.next_f32(), 0.05 + 0.4 * s.next_f32())).collect();
        let with_tree = SpecularTargets::new(list.clone());
        assert!(with_tree.tree.is_some());
        let without = SpecularTargets { tree: None, ..with_tree.clone() };
        let (mut passed, mut on_lines) = (0, 0);
        for k in 0..20_000 {
            let target = list[k % list.len()];
            let (u1, u2) = (s.next_2d(), s.next_2d());
            let aim = |targets| Targets { targets, target, target_pick: 1.0 / 300.0, u1, u2, scene_radius: 10.0 };
            let (tree, all) = (aim(&with_tree), aim(&without));
            let origin = uniform_sphere(s.next_2d()) * 9.0;
            // Half aimed at the drawn target's sphere (its edge too), half anywhere
            let direction = match k % 2 {
                0 => (target.0 + uniform_sphere(s.next_2d()) * target.1 * 1.05 - origin).normalize(),
                _ => uniform_sphere(s.next_2d()),
            };
            let pdf = all.direction_pdf(origin, direction);
            assert_eq!(tree.direction_pdf(origin, direction).to_bits(), pdf.to_bits(), "photon {k}");
            passed += (pdf > 0.0) as u32;
            let ((start, density), (tree_start, tree_density)) = (all.upstream(direction), tree.upstream(direction));
            assert_eq!((tree_start, tree_density.to_bits()), (start, density.to_bits()), "photon {k}");
            on_lines += (density > target_pick_of(&all)) as u32;
        }
        // Most aimed photons pass their target, and many lines pass several
        assert!(passed > 8_000 && on_lines > 2_000, "{passed} photons passed targets, {on_lines} lines several");
    }

    fn target_pick_of(targets: &Targets) -> f32 {
        targets.target_pick / (PI * targets.target.1 * targets.target.1)
    }
}
