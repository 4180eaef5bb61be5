//! What the tests share: small scenes built in code, and renders checked
//! for non-finite pixels.
#![allow(dead_code)]

pub mod detectors;
pub mod stats;

use std::sync::Arc;

use gi_studio::render::world::rng::Sampler;
use gi_studio::render::world::sampling::uniform_sphere;
use gi_studio::render::{render_blocking, Algorithm, LinearImage, RenderJob, RenderSettings};
use gi_studio::scene::*;
use glam::Vec3;

pub fn camera(position: Vec3, look_at: Vec3) -> Camera {
    Camera {
        position,
        look_at,
        up: Vec3::Y,
        fov_y_degrees: 40.0,
        near_clip: 0.0,
        near_clip_along: ClipAlong::ViewAxis,
        aperture_radius: 0.0,
        focus_distance: 0.0,
    }
}

pub fn material(name: &str, model: MaterialModel) -> Material {
    Material { name: name.into(), model }
}

pub fn object(name: &str, shape: Shape, material: &str) -> Object {
    Object { name: name.into(), shape, material: material.into() }
}

pub fn light(name: &str, kind: LightKind, intensity: f32) -> Light {
    Light { name: name.into(), kind, color: Vec3::ONE, intensity, attenuation: Attenuation::default(), enabled: true }
}

pub fn lambert(albedo: f32) -> MaterialModel {
    MaterialModel::Lambert { albedo: Vec3::splat(albedo) }
}

pub fn scene(camera: Camera, materials: Vec<Material>, objects: Vec<Object>, lights: Vec<Light>) -> Scene {
    Scene {
        camera,
        background: Vec3::ZERO,
        ambient: Vec3::ZERO,
        settings: SceneSettings { width: 32, height: 24, exposure: 0.0 },
        materials,
        objects,
        lights,
        meshes: Default::default(),
    }
}

/// A floor plane of albedo `albedo` seen from above.
pub fn floor_scene(albedo: f32, lights: Vec<Light>) -> Scene {
    scene(
        camera(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO),
        vec![material("floor", lambert(albedo))],
        vec![object("floor", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }, "floor")],
        lights,
    )
}

/// `scene`, checked: what the renderer takes.
pub fn valid(scene: impl Into<Scene>) -> ValidScene {
    ValidScene::new(scene.into()).expect("a valid scene")
}

pub fn mean_luminance(pixels: &[[f32; 3]]) -> f64 {
    pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).sum::<f64>() / pixels.len() as f64
}

pub fn random_direction(s: &mut Sampler) -> Vec3 {
    uniform_sphere(s.next_2d())
}

/// Settings for a test render: `spp` passes, a fixed seed.
pub fn settings(algorithm: Algorithm, width: u32, height: u32, spp: u32) -> RenderSettings {
    RenderSettings { width, height, samples_per_pixel: Some(spp), seed: 9, ..RenderSettings::for_algorithm(algorithm) }
}

/// Render, and insist no NaN or infinity reached the film; the count of
/// dropped non-finite samples.
pub fn render(scene: &Scene, settings: RenderSettings) -> (LinearImage, u64) {
    let (image, stats) = render_blocking(&RenderJob::new(Arc::new(valid(scene.clone())), settings)).expect("renders");
    assert!(image.pixels.iter().flatten().all(|c| c.is_finite()), "a non-finite pixel reached the film");
    (image, stats.non_finite)
}
