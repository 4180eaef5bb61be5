//! Every value checked before a scene reaches the engine, with a problem that
//! says what is wrong and a path that says where.

use std::collections::HashSet;

use glam::Vec3;

use super::differences::shown as shown_name;
use super::{LightKind, MaterialModel, Metal, Scene, Shape};
use crate::limits;

/// One invalid value: where it is (a readable path plus what the file locator
/// needs) and what is wrong with it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct Invalid {
    /// e.g. `objects[2] "glass ball".shape.radius`.
    pub field: String,
    /// Top-level section: `camera`, `settings`, `materials`, `objects`, `lights`.
    pub section: &'static str,
    /// The place of the list item in its section, when the value belongs to one.
    pub index: Option<usize>,
    /// The name of the list item, when the value belongs to one.
    pub item: Option<String>,
    /// The last field name on the path (`radius`).
    pub key: &'static str,
    pub problem: Problem,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Problem {
    #[error("must be a finite number, found {0}")]
    NotFinite(f32),
    #[error("must be greater than zero, found {0}")]
    NotPositive(f32),
    #[error("must not be negative, found {0}")]
    Negative(f32),
    #[error("must be between {min} and {max}, found {found}")]
    OutOfRange { min: f32, max: f32, found: f32 },
    #[error("cone angle must be in (0°, 90°], found {0}°")]
    ConeAngle(f32),
    #[error("must not be a zero-length vector")]
    ZeroLength,
    #[error("the up vector is parallel to the view direction")]
    UpParallelToView,
    #[error("attenuation a = b = c = 0 would divide by zero")]
    ZeroAttenuation,
    #[error("refers to material \"{0}\", which the scene does not define")]
    UnknownMaterial(String),
    #[error("the name \"{0}\" is used twice")]
    DuplicateName(String),
    #[error("must not be empty")]
    EmptyName,
    #[error("the mesh file \"{0}\" is not loaded (open the scene from its file, beside the mesh)")]
    MeshNotLoaded(String),
    #[error(
        "with the meshes placed before it, {placed} triangles, more than the {} a scene may place",
        limits::PLACED_TRIANGLES
    )]
    TooManyPlaced { placed: usize },
    #[error("{width} × {height} is more than the {} pixels an image may have", limits::IMAGE_PIXELS)]
    TooManyPixels { width: u32, height: u32 },
}

struct Checker<'a> {
    found: Vec<Invalid>,
    section: &'static str,
    index: Option<usize>,
    item: Option<&'a str>,
    prefix: String,
}

impl<'a> Checker<'a> {
    fn at(&mut self, section: &'static str, index: Option<usize>, item: Option<&'a str>, middle: &str) {
        self.section = section;
        self.index = index;
        self.item = item;
        self.prefix = match (index, item) {
            (Some(i), Some(name)) => format!("{section}[{i}] \"{}\"{middle}", shown_name(name)),
            (Some(i), None) => format!("{section}[{i}]{middle}"),
            _ => format!("{section}{middle}"),
        };
    }

    fn report(&mut self, key: &'static str, problem: Problem) {
        self.found.push(Invalid {
            field: format!("{}.{key}", self.prefix),
            section: self.section,
            index: self.index,
            item: self.item.map(str::to_owned),
            key,
            problem,
        });
    }

    fn finite(&mut self, key: &'static str, v: f32) -> bool {
        if v.is_finite() {
            return true;
        }
        self.report(key, Problem::NotFinite(v));
        false
    }

    fn vector(&mut self, key: &'static str, v: Vec3) -> bool {
        v.to_array().iter().all(|c| self.finite(key, *c))
    }

    fn direction(&mut self, key: &'static str, v: Vec3) {
        if self.vector(key, v) && v.length_squared() == 0.0 {
            self.report(key, Problem::ZeroLength);
        }
    }

    fn positive(&mut self, key: &'static str, v: f32) {
        if self.finite(key, v) && v <= 0.0 {
            self.report(key, Problem::NotPositive(v));
        }
    }

    fn non_negative(&mut self, key: &'static str, v: f32) {
        if self.finite(key, v) && v < 0.0 {
            self.report(key, Problem::Negative(v));
        }
    }

    fn within(&mut self, key: &'static str, v: f32, limit: limits::Limit<f32>) {
        if self.finite(key, v) && !limit.contains(v) {
            self.report(key, Problem::OutOfRange { min: limit.min, max: limit.max, found: v });
        }
    }

    fn colour(&mut self, key: &'static str, v: Vec3) {
        if self.vector(key, v) {
            if let Some(c) = v.to_array().into_iter().find(|c| *c < 0.0) {
                self.report(key, Problem::Negative(c));
            }
        }
    }

    fn reflectance(&mut self, key: &'static str, v: Vec3) {
        if self.vector(key, v) {
            if let Some(c) = v.to_array().into_iter().find(|c| !(0.0..=1.0).contains(c)) {
                self.report(key, Problem::OutOfRange { min: 0.0, max: 1.0, found: c });
            }
        }
    }

    fn name(&mut self, seen: &mut HashSet<&'a str>, name: &'a str) {
        if name.trim().is_empty() {
            self.report("name", Problem::EmptyName);
        } else if !seen.insert(name) {
            self.report("name", Problem::DuplicateName(shown_name(name)));
        }
    }
}

pub(super) fn validate(scene: &Scene) -> Vec<Invalid> {
    let mut check = Checker { found: Vec::new(), section: "camera", index: None, item: None, prefix: String::new() };

    let camera = &scene.camera;
    check.at("camera", None, None, "");
    let placed = check.vector("position", camera.position) & check.vector("look_at", camera.look_at);
    if check.vector("up", camera.up) {
        if camera.up.length_squared() == 0.0 {
            check.report("up", Problem::ZeroLength);
        } else if placed {
            let view = camera.look_at - camera.position;
            if view.length_squared() == 0.0 {
                check.report("look_at", Problem::ZeroLength);
            } else if view.normalize().cross(camera.up.normalize()).length() < 1e-6 {
                check.report("up", Problem::UpParallelToView);
            }
        }
    }
    if check.finite("fov_y_degrees", camera.fov_y_degrees)
        && !(camera.fov_y_degrees > 0.0 && camera.fov_y_degrees < 180.0)
    {
        check.report("fov_y_degrees", Problem::OutOfRange { min: 0.0, max: 180.0, found: camera.fov_y_degrees });
    }
    check.non_negative("near_clip", camera.near_clip);
    check.non_negative("aperture_radius", camera.aperture_radius);
    check.non_negative("focus_distance", camera.focus_distance);

    check.at("settings", None, None, "");
    let side = limits::IMAGE_SIDE;
    for (key, v) in [("width", scene.settings.width), ("height", scene.settings.height)] {
        if !side.contains(v) {
            check.report(key, Problem::OutOfRange { min: side.min as f32, max: side.max as f32, found: v as f32 });
        }
    }
    let (width, height) = (scene.settings.width, scene.settings.height);
    if side.contains(width) && side.contains(height) && width as u64 * height as u64 > limits::IMAGE_PIXELS {
        check.report("height", Problem::TooManyPixels { width, height });
    }
    check.within("exposure", scene.settings.exposure, limits::EXPOSURE_STOPS);
    check.at("scene", None, None, "");
    check.colour("background", scene.background);
    check.colour("ambient", scene.ambient);

    let mut names = HashSet::new();
    for (i, material) in scene.materials.iter().enumerate() {
        check.at("materials", Some(i), Some(&material.name), "");
        check.name(&mut names, &material.name);
        check.at("materials", Some(i), Some(&material.name), ".model");
        match &material.model {
            MaterialModel::Lambert { albedo } => check.reflectance("albedo", *albedo),
            MaterialModel::Phong { ka, kd, ks, shininess } | MaterialModel::BlinnPhong { ka, kd, ks, shininess } => {
                check.reflectance("ka", *ka);
                check.reflectance("kd", *kd);
                check.reflectance("ks", *ks);
                check.non_negative("shininess", *shininess);
            }
            MaterialModel::Mirror { tint } => check.reflectance("tint", *tint),
            MaterialModel::Glass { ior, tint } => {
                check.positive("ior", *ior);
                check.reflectance("tint", *tint);
            }
            MaterialModel::Conductor { metal, alpha_u, alpha_v } => {
                check.within("alpha_u", *alpha_u, limits::ROUGHNESS);
                check.within("alpha_v", *alpha_v, limits::ROUGHNESS);
                if let Metal::Custom { eta, k } = metal {
                    check.at("materials", Some(i), Some(&material.name), ".model.metal");
                    for (key, v) in [("eta", eta), ("k", k)] {
                        v.to_array().into_iter().for_each(|c| check.within(key, c, limits::METAL_INDEX));
                    }
                }
            }
            MaterialModel::Emissive { radiance } => check.colour("radiance", *radiance),
        }
    }

    let mut names = HashSet::new();
    let mut placed = 0usize;
    for (i, object) in scene.objects.iter().enumerate() {
        check.at("objects", Some(i), Some(&object.name), "");
        check.name(&mut names, &object.name);
        if scene.material_index(&object.material).is_none() {
            check.report("material", Problem::UnknownMaterial(shown_name(&object.material)));
        }
        check.at("objects", Some(i), Some(&object.name), ".shape");
        match &object.shape {
            Shape::Sphere { center, radius } => {
                check.vector("center", *center);
                check.positive("radius", *radius);
            }
            Shape::Plane { point, normal } => {
                check.vector("point", *point);
                check.direction("normal", *normal);
            }
            // Degenerate triangles are allowed: they are never hit.
            Shape::Triangle { a, b, c } => {
                check.vector("a", *a);
                check.vector("b", *b);
                check.vector("c", *c);
            }
            Shape::Mesh { file, translate, scale, rotate_degrees } => {
                match scene.meshes.get(file) {
                    None => check.report("file", Problem::MeshNotLoaded(shown_name(file))),
                    Some(mesh) => {
                        // Reported once, at the placement that crosses the limit
                        let before = placed;
                        placed = placed.saturating_add(mesh.triangles.len());
                        if placed > limits::PLACED_TRIANGLES && before <= limits::PLACED_TRIANGLES {
                            check.report("file", Problem::TooManyPlaced { placed });
                        }
                    }
                }
                check.vector("translate", *translate);
                check.positive("scale", *scale);
                check.vector("rotate_degrees", *rotate_degrees);
            }
        }
    }

    let mut names = HashSet::new();
    for (i, light) in scene.lights.iter().enumerate() {
        check.at("lights", Some(i), Some(&light.name), "");
        check.name(&mut names, &light.name);
        check.colour("color", light.color);
        check.non_negative("intensity", light.intensity);
        let falloff = &light.attenuation;
        let directional = matches!(light.kind, LightKind::Directional { .. });
        check.at("lights", Some(i), Some(&light.name), ".attenuation");
        let finite = check.finite("a", falloff.a) & check.finite("b", falloff.b) & check.finite("c", falloff.c);
        if finite && !directional {
            if falloff.a < 0.0 || falloff.b < 0.0 || falloff.c < 0.0 {
                let key = if falloff.a < 0.0 {
                    "a"
                } else if falloff.b < 0.0 {
                    "b"
                } else {
                    "c"
                };
                check.report(key, Problem::Negative(falloff.a.min(falloff.b).min(falloff.c)));
            } else if falloff.a == 0.0 && falloff.b == 0.0 && falloff.c == 0.0 {
                check.report("a", Problem::ZeroAttenuation);
            }
        }
        check.at("lights", Some(i), Some(&light.name), ".kind");
        match &light.kind {
            LightKind::Point { position } => {
                check.vector("position", *position);
            }
            LightKind::Directional { direction } => check.direction("direction", *direction),
            LightKind::Spot { position, direction, cone_angle_degrees, falloff_exponent } => {
                check.vector("position", *position);
                check.direction("direction", *direction);
                if check.finite("cone_angle_degrees", *cone_angle_degrees)
                    && !(*cone_angle_degrees > 0.0 && *cone_angle_degrees <= 90.0)
                {
                    check.report("cone_angle_degrees", Problem::ConeAngle(*cone_angle_degrees));
                }
                check.non_negative("falloff_exponent", *falloff_exponent);
            }
        }
    }
    check.found
}
