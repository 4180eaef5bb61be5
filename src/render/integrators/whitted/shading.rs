//! What a Whitted ray does at its hit, written once for the recursion and
//! for the tile renderer that traces a tile's rays wave by wave: the rays it
//! spawns (`branches`), the thesis' local model toward one light
//! (`light_term`), and how its light and its children's combine
//! (`combine`). What each material does is its own (`materials::Thesis`).

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use crate::geometry::Ray;
use crate::render::world::light::LightSample;
use crate::render::world::materials::{reflect, At, Brought, Bsdf};
use crate::render::world::{Hit, World};
use crate::scene::Rgb;

/// Below this path weight a reflection adds nothing visible.
const MIN_WEIGHT: f32 = 1e-3;

/// The rays a hit spawns, with their weights: a mirror's, a Phong
/// highlight's or glass's reflection, glass's refraction.
#[derive(Clone, Copy, Debug, Default)]
pub struct Branches {
    pub reflected: Option<(Ray, f32)>,
    pub refracted: Option<(Ray, f32)>,
}

/// The way back, the normal and it turned to face the way back, at a ray's hit.
#[inline]
pub fn at(ray: &Ray, hit: &Hit) -> At<f32> {
    At::new(-ray.direction, hit.surface.normal)
}

/// The rays `ray`'s hit spawns, `depth_left` levels left, its light
/// weighing `weight` at the camera.
pub fn branches(world: &World, ray: &Ray, hit: &Hit, depth_left: u32, weight: f32) -> Branches {
    if depth_left <= 1 {
        return Branches::default();
    }
    let at = at(ray, hit);
    let (wo, facing) = (at.wo.into(), at.facing.into());
    let shares = Bsdf::new(world.material_of(hit)).thesis_shares(&at);
    let reflected = weight * shares.reflected;
    let reflected = (reflected > MIN_WEIGHT).then(|| (hit.surface.spawn_ray(reflect(wo, facing)), reflected));
    let refracted = shares.refracted.map(|(wt, share)| (hit.surface.spawn_ray(wt), weight * share));
    Branches { reflected, refracted: refracted.filter(|&(_, w)| w > MIN_WEIGHT) }
}

/// The local model toward one light sample at cosine `cos`, the light's
/// colour its irradiance over π (the thesis' `Ld`). Zero where the
/// material is not lit (`Bsdf::thesis_lit`).
pub fn light_term(bsdf: &Bsdf, at: &At<f32>, sample: &LightSample, cos: f32) -> Rgb {
    let light_colour = sample.value * FRAC_1_PI;
    light_colour * bsdf.thesis_local(at, sample.wi, cos)
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
    local: Rgb,
    [reflected, refracted]: [Rgb; 2],
    branches: &Branches,
) -> Rgb {
    let at = at(ray, hit);
    let material = world.material_of(hit);
    let ambient = material.ambient_colour() * world.ambient;
    let brought =
        Brought { reflected: branches.reflected.map(|_| reflected), refracted: branches.refracted.map(|_| refracted) };
    let combined = Bsdf::new(material).thesis_combine(ambient, local, brought, &at);
    combined.unwrap_or_else(|| world.emitted(hit, at.wo.into()))
}
