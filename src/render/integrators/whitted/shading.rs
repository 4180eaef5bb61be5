//! What a Whitted ray does at its hit, written once for the recursion and
//! for the tile renderer that traces a tile's rays wave by wave: the rays it
//! spawns (`branches`), the thesis' local model toward one light
//! (`light_term`), and how its light and its children's combine
//! (`combine`).

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use crate::geometry::{pow, Ray};
use crate::render::world::bsdf::{reflect, refract};
use crate::render::world::light::LightSample;
use crate::render::world::{Hit, World};
use crate::scene::{MaterialModel, Rgb};

/// Below this path weight a reflection adds nothing visible.
const MIN_WEIGHT: f32 = 1e-3;

/// The rays a hit spawns, with their weights: a mirror's, a Phong
/// highlight's or glass's reflection, glass's refraction.
#[derive(Clone, Copy, Debug, Default)]
pub struct Branches {
    pub reflected: Option<(Ray, f32)>,
    pub refracted: Option<(Ray, f32)>,
}

/// The facing normal and the way back of a ray's hit.
#[inline]
pub fn facing(ray: &Ray, hit: &Hit) -> (Vec3, Vec3) {
    let (wo, n) = (-ray.direction, hit.surface.normal);
    (if wo.dot(n) < 0.0 { -n } else { n }, wo)
}

/// Whether the local model is lit at this material (and so draws a light
/// sample per light).
#[inline]
pub fn shades(material: &MaterialModel) -> bool {
    matches!(material, MaterialModel::Lambert { .. } | MaterialModel::Phong { .. } | MaterialModel::BlinnPhong { .. })
}

/// The rays `ray`'s hit spawns, `depth_left` levels left, its light
/// weighing `weight` at the camera.
pub fn branches(world: &World, ray: &Ray, hit: &Hit, depth_left: u32, weight: f32) -> Branches {
    let (facing, wo) = facing(ray, hit);
    let can_recurse = depth_left > 1;
    let mirror = |w: f32| (can_recurse && w > MIN_WEIGHT).then(|| (hit.surface.spawn_ray(reflect(wo, facing)), w));
    match *world.material_of(hit) {
        MaterialModel::Emissive { .. } | MaterialModel::Lambert { .. } => Branches::default(),
        MaterialModel::Phong { ks, .. } | MaterialModel::BlinnPhong { ks, .. } => {
            Branches { reflected: mirror(weight * ks.max_element()), refracted: None }
        }
        MaterialModel::Mirror { tint } => Branches { reflected: mirror(weight * tint.max_element()), refracted: None },
        MaterialModel::Glass { ior, .. } => {
            if !can_recurse {
                return Branches::default();
            }
            let n = hit.surface.normal;
            let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, ior) } else { (ior, 1.0) };
            let (fresnel, refracted, _) = refract(wo, facing, eta_i, eta_t);
            let reflected =
                (weight * fresnel > MIN_WEIGHT).then(|| (hit.surface.spawn_ray(reflect(wo, facing)), weight * fresnel));
            let refracted = refracted
                .map(|wt| (hit.surface.spawn_ray(wt), weight * (1.0 - fresnel)))
                .filter(|&(_, w)| w > MIN_WEIGHT);
            Branches { reflected, refracted }
        }
    }
}

/// The local model toward one light sample at cosine `cos`: the thesis'
/// `kd·Ld·(l·n) + ks·Ls·(r·v)^α` (Blinn–Phong's `(n·h)^α`), its `Ld` the
/// light's irradiance over π. Zero where the material is not lit.
pub fn light_term(material: &MaterialModel, n: Vec3, wo: Vec3, sample: &LightSample, cos: f32) -> Rgb {
    let (kd, ks, exponent, blinn) = match *material {
        MaterialModel::Lambert { albedo } => (albedo, Rgb::ZERO, 0.0, false),
        MaterialModel::Phong { kd, ks, shininess, .. } => (kd, ks, shininess, false),
        MaterialModel::BlinnPhong { kd, ks, shininess, .. } => (kd, ks, shininess, true),
        _ => return Rgb::ZERO,
    };
    let light_colour = sample.value * FRAC_1_PI;
    let mut c = kd * cos;
    if ks != Rgb::ZERO {
        let highlight = if blinn { n.dot((sample.wi + wo).normalize()) } else { reflect(sample.wi, n).dot(wo) };
        c += ks * pow::powf(highlight.max(0.0), exponent);
    }
    light_colour * c
}

/// A light sample's cosine at the lit point, where it can light it (a NaN
/// goes on, to be counted and dropped).
#[inline]
pub fn lit_cosine(n: Vec3, sample: &LightSample) -> Option<f32> {
    let cos = n.dot(sample.wi);
    (cos > 0.0 || cos.is_nan()).then_some(cos)
}

/// The light leaving `ray`'s hit toward the camera: the local model's
/// `local` (over every light) and the light its branches brought back
/// (`brought`: the reflection's and the refraction's, zero where there
/// was none).
pub fn combine(
    world: &World,
    ray: &Ray,
    hit: &Hit,
    depth_left: u32,
    local: Rgb,
    [reflected, refracted]: [Rgb; 2],
    branches: &Branches,
) -> Rgb {
    let (facing, wo) = facing(ray, hit);
    match *world.material_of(hit) {
        MaterialModel::Emissive { .. } => world.emitted(hit, wo),
        MaterialModel::Lambert { albedo } => albedo * world.ambient + local,
        MaterialModel::Phong { ka, ks, .. } | MaterialModel::BlinnPhong { ka, ks, .. } => {
            let mut c = ka * world.ambient + local;
            // The thesis' loop: the surface's reflectivity scales a mirror bounce
            if branches.reflected.is_some() {
                c += ks * reflected;
            }
            c
        }
        MaterialModel::Mirror { tint } => match branches.reflected {
            Some(_) => tint * reflected,
            None => Rgb::ZERO,
        },
        MaterialModel::Glass { ior, tint } => {
            if depth_left <= 1 {
                return Rgb::ZERO;
            }
            let n = hit.surface.normal;
            let (eta_i, eta_t) = if wo.dot(n) > 0.0 { (1.0, ior) } else { (ior, 1.0) };
            let (fresnel, _, eta) = refract(wo, facing, eta_i, eta_t);
            let mut c = Rgb::ZERO;
            if branches.reflected.is_some() {
                c += fresnel * reflected;
            }
            if branches.refracted.is_some() {
                // Radiance is compressed by η² crossing into the denser side
                c += (1.0 - fresnel) * eta * eta * refracted;
            }
            tint * c
        }
    }
}
