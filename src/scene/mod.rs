//! The scene as the user edits and saves it: camera, background, materials,
//! objects and lights. Closed sets are enums (all variants visible here); the
//! whole scene is `Clone + Send` so the engine renders from snapshots.

mod differences;
mod file;
pub mod mesh;
pub mod presets;
mod valid;
mod validate;

pub use differences::{differences, shown as shown_name};
pub use file::{load_scene, parse_scene, parse_scene_with, save_scene, to_ron, SceneFileError};
pub use valid::ValidScene;
pub use validate::{Invalid, Problem};

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Linear RGB radiance, reflectance or power. An alias rather than a newtype:
/// colours need the same arithmetic as vectors; names say which is which.
pub type Rgb = Vec3;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub camera: Camera,
    /// Radiance of rays that leave the scene.
    #[serde(default)]
    pub background: Rgb,
    /// Ambient light `La` of the thesis' local models (Whitted only).
    #[serde(default)]
    pub ambient: Rgb,
    #[serde(default)]
    pub settings: SceneSettings,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    #[serde(default)]
    pub lights: Vec<Light>,
    /// The files its meshes name, loaded (by the scene file's loader, or
    /// the studio's import); not part of its text.
    #[serde(skip)]
    pub meshes: mesh::Meshes,
}

/// A pinhole or thin-lens camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
    /// Primary rays start this far from the camera (smallpt's `+d*140`),
    /// measured as `near_clip_along` says; 0 starts them at the camera.
    #[serde(default)]
    pub near_clip: f32,
    /// How `near_clip` is measured: along the view axis (rays start on a
    /// plane, the default) or along each ray (on a sphere about the eye,
    /// as smallpt's `cam.o + d*140` with `d` already normalised does).
    #[serde(default, skip_serializing_if = "ClipAlong::is_view_axis")]
    pub near_clip_along: ClipAlong,
    /// Thin-lens radius; 0 is a pinhole.
    #[serde(default)]
    pub aperture_radius: f32,
    /// Distance of the plane in focus; 0 focuses on `look_at`.
    #[serde(default)]
    pub focus_distance: f32,
}

/// Where a camera's near clip is measured; see `Camera::near_clip_along`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClipAlong {
    /// Rays start on the plane `near_clip` along the view axis.
    #[default]
    ViewAxis,
    /// Rays start `near_clip` along themselves.
    Ray,
}

impl ClipAlong {
    pub fn is_view_axis(&self) -> bool {
        *self == Self::ViewAxis
    }
}

/// What a scene asks of the image by default (flags may override).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneSettings {
    pub width: u32,
    pub height: u32,
    /// Exposure in stops applied before tone mapping.
    pub exposure: f32,
}

impl Default for SceneSettings {
    fn default() -> Self {
        Self { width: 640, height: 480, exposure: 0.0 }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    pub model: MaterialModel,
}

/// Surface models. Lambert, Phong and Blinn–Phong are the thesis' local
/// models: Whitted uses them as written, the Monte Carlo algorithms as
/// energy-conserving (normalised) BRDFs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MaterialModel {
    Lambert {
        albedo: Rgb,
    },
    Phong {
        ka: Rgb,
        kd: Rgb,
        ks: Rgb,
        shininess: f32,
    },
    BlinnPhong {
        ka: Rgb,
        kd: Rgb,
        ks: Rgb,
        shininess: f32,
    },
    Mirror {
        tint: Rgb,
    },
    Glass {
        ior: f32,
        tint: Rgb,
    },
    /// A metal: Fresnel's reflection of `metal`'s complex index on GGX
    /// microfacets of roughness α (the slopes' width, as Mitsuba and pbrt
    /// take it; `alpha_u` along the first axis of the frame about the
    /// normal, `alpha_v` along the second); both below
    /// `SMOOTH_ALPHA` is a polished metal, a mirror whose colour is Fresnel's.
    Conductor {
        metal: Metal,
        alpha_u: f32,
        alpha_v: f32,
    },
    /// A black surface that emits `radiance` from its front side (outward for
    /// spheres, along the normal for planes and triangles): an area light.
    Emissive {
        radiance: Rgb,
    },
}

impl MaterialModel {
    pub fn kind_name(&self) -> &'static str {
        match self {
            Self::Lambert { .. } => "Lambert",
            Self::Phong { .. } => "Phong",
            Self::BlinnPhong { .. } => "Blinn–Phong",
            Self::Mirror { .. } => "Mirror",
            Self::Glass { .. } => "Glass",
            Self::Conductor { .. } => "Metal",
            Self::Emissive { .. } => "Emissive",
        }
    }

    /// The thesis' ambient colour: the share of the scene's ambient light
    /// a surface gives back (only Whitted's models read it).
    pub fn ambient_colour(&self) -> Rgb {
        match *self {
            Self::Lambert { albedo } => albedo,
            Self::Phong { ka, .. } | Self::BlinnPhong { ka, .. } => ka,
            Self::Conductor { metal, .. } => metal.normal_reflectance(),
            Self::Mirror { .. } | Self::Glass { .. } | Self::Emissive { .. } => Rgb::ZERO,
        }
    }

    /// Only delta lobes: mirrors, glass and polished metals.
    pub fn is_specular(&self) -> bool {
        match *self {
            Self::Mirror { .. } | Self::Glass { .. } => true,
            Self::Conductor { alpha_u, alpha_v, .. } => alpha_u.max(alpha_v) < SMOOTH_ALPHA,
            Self::Lambert { .. } | Self::Phong { .. } | Self::BlinnPhong { .. } | Self::Emissive { .. } => false,
        }
    }
}

/// Below this roughness a metal is polished: its lobe would be narrower
/// than a pixel's worth of directions and sampling lights toward it wasted.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// A conductor's complex index of refraction η + ik per RGB channel. The
/// named metals' values are measured spectra (Palik's, as Mitsuba 3
/// ships them) reduced to RGB the way Mitsuba's RGB variants reduce them,
/// so a metal renders the colour it has there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Metal {
    Gold,
    Silver,
    Copper,
    Aluminium,
    Custom { eta: Rgb, k: Rgb },
}

impl Metal {
    pub const NAMED: [Metal; 4] = [Metal::Gold, Metal::Silver, Metal::Copper, Metal::Aluminium];

    /// (η, k).
    pub fn index(&self) -> (Rgb, Rgb) {
        match *self {
            Metal::Gold => (Vec3::new(0.143_036, 0.375_307, 1.442_05), Vec3::new(3.983, 2.385_56, 1.603_36)),
            Metal::Silver => (Vec3::new(0.155_276, 0.116_728, 0.138_388), Vec3::new(4.828_35, 3.122_22, 2.146_9)),
            Metal::Copper => (Vec3::new(0.201_005, 0.923_75, 1.102_22), Vec3::new(3.913_26, 2.453_05, 2.142_09)),
            Metal::Aluminium => (Vec3::new(1.657_5, 0.880_405, 0.521_244), Vec3::new(9.223_81, 6.269_5, 4.837)),
            Metal::Custom { eta, k } => (eta, k),
        }
    }

    pub fn label(&self) -> &'static str {
        match self {
            Metal::Gold => "Gold",
            Metal::Silver => "Silver",
            Metal::Copper => "Copper",
            Metal::Aluminium => "Aluminium",
            Metal::Custom { .. } => "Custom",
        }
    }

    /// Fresnel's reflectance at normal incidence, ((η−1)² + k²)/((η+1)² + k²):
    /// the metal's colour.
    pub fn normal_reflectance(&self) -> Rgb {
        let (eta, k) = self.index();
        let k2 = k * k;
        ((eta - Vec3::ONE) * (eta - Vec3::ONE) + k2) / ((eta + Vec3::ONE) * (eta + Vec3::ONE) + k2)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    /// Name of an entry of `Scene::materials`.
    pub material: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Shape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// The infinite plane through `point` facing `normal`.
    Plane {
        point: Vec3,
        normal: Vec3,
    },
    /// Front side given by the winding: normal ∝ (b − a) × (c − a).
    Triangle {
        a: Vec3,
        b: Vec3,
        c: Vec3,
    },
    /// The triangles of an OBJ or PLY file (its path relative to the scene
    /// file's folder), scaled by `scale` about the file's origin, turned by
    /// `rotate_degrees` about x, then y, then z, then moved by `translate`.
    Mesh {
        file: String,
        #[serde(default)]
        translate: Vec3,
        #[serde(default = "unit_scale")]
        scale: f32,
        #[serde(default)]
        rotate_degrees: Vec3,
    },
}

fn unit_scale() -> f32 {
    1.0
}

impl Shape {
    /// Where a mesh's file puts its points (`Mesh`'s placement: scale,
    /// then turn about x, y, z, then move); nothing for any other shape.
    pub fn placement(&self) -> glam::Affine3A {
        match *self {
            Shape::Mesh { translate, scale, rotate_degrees, .. } => {
                let r = rotate_degrees * (std::f32::consts::PI / 180.0);
                let rotation = glam::Quat::from_euler(glam::EulerRot::ZYX, r.z, r.y, r.x);
                glam::Affine3A::from_scale_rotation_translation(Vec3::splat(scale), rotation, translate)
            }
            _ => glam::Affine3A::IDENTITY,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    pub color: Rgb,
    /// Scales `color`: radiant intensity (W/sr) for point and spot lights,
    /// irradiance at normal incidence for directional lights.
    pub intensity: f32,
    /// Distance falloff `1/(a·d² + b·d + c)`; ignored by directional lights.
    #[serde(default)]
    pub attenuation: Attenuation,
    #[serde(default = "enabled_by_default")]
    pub enabled: bool,
}

fn enabled_by_default() -> bool {
    true
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightKind {
    Point {
        position: Vec3,
    },
    /// Light from infinitely far away travelling along `direction`.
    Directional {
        direction: Vec3,
    },
    /// A point light restricted to a cone around `direction`, with the
    /// thesis' falloff `(Vp·Va)^σ` inside it.
    Spot {
        position: Vec3,
        direction: Vec3,
        cone_angle_degrees: f32,
        falloff_exponent: f32,
    },
}

impl LightKind {
    pub fn kind_name(&self) -> &'static str {
        match self {
            Self::Point { .. } => "Point",
            Self::Directional { .. } => "Directional",
            Self::Spot { .. } => "Spot",
        }
    }
}

/// Coefficients of `1/(a·d² + b·d + c)`; the default is the physical `1/d²`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Attenuation {
    pub a: f32,
    pub b: f32,
    pub c: f32,
}

impl Default for Attenuation {
    fn default() -> Self {
        Self { a: 1.0, b: 0.0, c: 0.0 }
    }
}

impl Attenuation {
    #[inline]
    pub fn factor(&self, distance: f32) -> f32 {
        1.0 / (self.a * distance * distance + self.b * distance + self.c)
    }
}

impl Scene {
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }

    /// Every problem with the scene, in document order; empty when it can be
    /// rendered.
    pub fn validate(&self) -> Vec<Invalid> {
        validate::validate(self)
    }

    /// A stable 64-bit key of the scene's content (FNV-1a of its RON form,
    /// then of each mesh's own key: a mesh file changed under the same name
    /// is another scene), used to tie saved photon maps and references to
    /// the scene they belong to.
    pub fn content_key(&self) -> u64 {
        let text = to_ron(self).unwrap_or_default();
        let meshes = self.meshes.keys().flat_map(u64::to_le_bytes);
        (text.bytes().chain(meshes)).fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
    }
}
