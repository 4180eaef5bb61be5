//! The scene inspector: lists of objects, materials and lights, and the
//! selected item's properties as drag values, colour pickers and combo
//! boxes. It edits the scene in place; the studio validates every change
//! before any of it reaches the engine.

use eframe::egui;
use glam::Vec3;

use super::document::{unique_name, Spot};
use super::widgets::{committed_text_ui, number, slider};

use crate::limits;
use crate::scene::{
    Attenuation, ClipAlong, Invalid, Light, LightKind, Material, MaterialModel, Metal, Object, Scene, Shape,
};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Selection {
    #[default]
    Camera,
    Object(usize),
    Material(usize),
    Light(usize),
}

/// Draw the inspector; returns whether the scene changed.
/// Draw the inspector; returns whether the scene changed. New objects go
/// to `spot`, where the centre of the view meets the scene.
pub fn inspector_ui(
    ui: &mut egui::Ui,
    scene: &mut Scene,
    selection: &mut Selection,
    problems: &[Invalid],
    spot: Spot,
) -> bool {
    if !problems.is_empty() {
        egui::Frame::new().fill(ui.visuals().extreme_bg_color).inner_margin(6.0).show(ui, |ui| {
            ui.colored_label(ui.visuals().error_fg_color, "Not rendered until fixed:");
            for problem in problems {
                ui.colored_label(ui.visuals().error_fg_color, problem.to_string());
            }
        });
    }
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.selectable_value(selection, Selection::Camera, "Camera");
            let listed = list_ui(ui, scene, selection, spot);
            ui.separator();
            ui.heading(selected_title(scene, *selection));
            listed | properties_ui(ui, scene, selection)
        })
        .inner
}

fn selected_title(scene: &Scene, selection: Selection) -> String {
    match selection {
        Selection::Camera => "Camera".into(),
        Selection::Object(i) => scene.objects.get(i).map_or("—".into(), |o| format!("Object “{}”", o.name)),
        Selection::Material(i) => scene.materials.get(i).map_or("—".into(), |m| format!("Material “{}”", m.name)),
        Selection::Light(i) => scene.lights.get(i).map_or("—".into(), |l| format!("Light “{}”", l.name)),
    }
}

/// Up to how many objects the list shows whole; a longer one scrolls in a
/// box of its own, drawing only the rows in view.
const LISTED_OBJECTS: usize = 64;

/// The lists with their add, duplicate and delete buttons.
fn list_ui(ui: &mut egui::Ui, scene: &mut Scene, selection: &mut Selection, spot: Spot) -> bool {
    let before = (scene.objects.len(), scene.materials.len(), scene.lights.len());
    let mut toggled = false;
    egui::CollapsingHeader::new("Objects").default_open(true).show(ui, |ui| {
        let row = |ui: &mut egui::Ui, i: usize, selection: &mut Selection| {
            let object = &scene.objects[i];
            ui.selectable_value(
                selection,
                Selection::Object(i),
                format!("{} ({})", object.name, shape_name(&object.shape)),
            );
        };
        if scene.objects.len() <= LISTED_OBJECTS {
            (0..scene.objects.len()).for_each(|i| row(ui, i, selection));
        } else {
            // Only the rows in view are laid out: a scene of 100,000 balls
            // took seconds a frame to list them all
            let height = ui.spacing().interact_size.y;
            egui::ScrollArea::vertical().id_salt("objects").max_height(height * 16.0).show_rows(
                ui,
                height,
                scene.objects.len(),
                |ui, rows| rows.for_each(|i| row(ui, i, selection)),
            );
        }
        ui.horizontal(|ui| {
            ui.menu_button("Add", |ui| {
                let material = scene.materials.first().map(|m| m.name.clone()).unwrap_or_default();
                let shapes = [
                    ("Sphere", sphere_at(spot)),
                    ("Plane", Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y }),
                    ("Triangle", triangle_at(spot)),
                ];
                for (label, shape) in shapes {
                    if ui.button(label).clicked() {
                        let name = unique_name(&label.to_lowercase(), |n| scene.objects.iter().any(|o| o.name == n));
                        scene.objects.push(Object { name, shape, material: material.clone() });
                        *selection = Selection::Object(scene.objects.len() - 1);
                        ui.close();
                    }
                }
            });
            if let Selection::Object(i) = *selection {
                if i < scene.objects.len() {
                    if ui.button("Duplicate").clicked() {
                        let mut copy = scene.objects[i].clone();
                        copy.name = unique_name(&copy.name, |n| scene.objects.iter().any(|o| o.name == n));
                        scene.objects.insert(i + 1, copy);
                        *selection = Selection::Object(i + 1);
                    }
                    if ui.button("Delete").clicked() {
                        scene.objects.remove(i);
                        *selection = Selection::Camera;
                    }
                }
            }
        });
    });
    egui::CollapsingHeader::new("Materials").default_open(true).show(ui, |ui| {
        for (i, material) in scene.materials.iter().enumerate() {
            ui.selectable_value(
                selection,
                Selection::Material(i),
                format!("{} ({})", material.name, material.model.kind_name()),
            );
        }
        ui.horizontal(|ui| {
            if ui.button("Add").clicked() {
                let name = unique_name("material", |n| scene.materials.iter().any(|m| m.name == n));
                scene.materials.push(Material { name, model: MaterialModel::Lambert { albedo: Vec3::splat(0.7) } });
                *selection = Selection::Material(scene.materials.len() - 1);
            }
            if let Selection::Material(i) = *selection {
                if i < scene.materials.len() {
                    if ui.button("Duplicate").clicked() {
                        let mut copy = scene.materials[i].clone();
                        copy.name = unique_name(&copy.name, |n| scene.materials.iter().any(|m| m.name == n));
                        scene.materials.insert(i + 1, copy);
                        *selection = Selection::Material(i + 1);
                    }
                    let used = scene.objects.iter().any(|o| o.material == scene.materials[i].name);
                    let delete = ui.add_enabled(!used, egui::Button::new("Delete"));
                    if delete.on_disabled_hover_text("Objects still use this material").clicked() {
                        scene.materials.remove(i);
                        *selection = Selection::Camera;
                    }
                }
            }
        });
    });
    egui::CollapsingHeader::new("Lights").default_open(true).show(ui, |ui| {
        for (i, light) in scene.lights.iter_mut().enumerate() {
            ui.horizontal(|ui| {
                let checkbox = ui.checkbox(&mut light.enabled, "");
                toggled |= checkbox.changed();
                checkbox.on_hover_text("Enabled").widget_info(|| {
                    egui::WidgetInfo::selected(
                        egui::Role::CheckBox,
                        true,
                        light.enabled,
                        format!("{} enabled", light.name),
                    )
                });
                ui.selectable_value(
                    selection,
                    Selection::Light(i),
                    format!("{} ({})", light.name, light.kind.kind_name()),
                );
            });
        }
        ui.horizontal(|ui| {
            if ui.button("Add").clicked() {
                let name = unique_name("light", |n| scene.lights.iter().any(|l| l.name == n));
                scene.lights.push(Light {
                    name,
                    kind: LightKind::Point { position: Vec3::new(0.0, 3.0, 2.0) },
                    color: Vec3::ONE,
                    intensity: 10.0,
                    attenuation: Attenuation::default(),
                    enabled: true,
                });
                *selection = Selection::Light(scene.lights.len() - 1);
            }
            if let Selection::Light(i) = *selection {
                if i < scene.lights.len() {
                    if ui.button("Duplicate").clicked() {
                        let mut copy = scene.lights[i].clone();
                        copy.name = unique_name(&copy.name, |n| scene.lights.iter().any(|l| l.name == n));
                        scene.lights.insert(i + 1, copy);
                        *selection = Selection::Light(i + 1);
                    }
                    if ui.button("Delete").clicked() {
                        scene.lights.remove(i);
                        *selection = Selection::Camera;
                    }
                }
            }
        });
    });
    // One click a frame: an add, a duplicate or a delete changes a count
    toggled || (scene.objects.len(), scene.materials.len(), scene.lights.len()) != (before.0, before.1, before.2)
}

/// A sphere resting on the surface at `spot`, a twelfth of its distance
/// across: seen where the view's centre is, whatever the scene's scale.
pub fn sphere_at(spot: Spot) -> Shape {
    let radius = (spot.distance / 12.0).max(1e-3);
    Shape::Sphere { center: spot.point + spot.normal * radius, radius }
}

/// A triangle facing the camera just in front of the surface at `spot`.
pub fn triangle_at(spot: Spot) -> Shape {
    let size = (spot.distance / 8.0).max(1e-3);
    let centre = spot.point + spot.normal * (size * 0.5);
    // u × v = normal: the winding (b − a) × (c − a) faces the camera
    let u = spot.normal.any_orthonormal_vector();
    let v = spot.normal.cross(u);
    Shape::Triangle {
        a: centre - u * size - v * (0.6 * size),
        b: centre + u * size - v * (0.6 * size),
        c: centre + v * size,
    }
}

fn shape_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Sphere { .. } => "sphere",
        Shape::Plane { .. } => "plane",
        Shape::Triangle { .. } => "triangle",
        Shape::Mesh { .. } => "mesh",
    }
}

// Every widget function returns whether it changed the scene: the studio
// counts revisions by it instead of comparing the scene each frame.

fn vec3_ui(ui: &mut egui::Ui, label: &str, v: &mut Vec3, speed: f64) -> bool {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        let mut changed = false;
        for (axis, c) in ["x", "y", "z"].into_iter().zip([&mut v.x, &mut v.y, &mut v.z]) {
            changed |= ui.add(number(c).speed(speed).prefix(format!("{axis} "))).labelled_by(label.id).changed();
        }
        changed
    })
    .inner
}

fn scalar_ui(ui: &mut egui::Ui, label: &str, v: &mut f32, range: std::ops::RangeInclusive<f32>, speed: f64) -> bool {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        ui.add(number(v).speed(speed).range(range)).labelled_by(label.id).changed()
    })
    .inner
}

/// A reflectance in [0, 1]: a colour picker.
fn reflectance_ui(ui: &mut egui::Ui, label: &str, v: &mut Vec3) -> bool {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        let mut rgb = v.to_array();
        let mut changed = false;
        if ui.color_edit_button_rgb(&mut rgb).labelled_by(label.id).changed() {
            *v = Vec3::from_array(rgb).clamp(Vec3::ZERO, Vec3::ONE);
            changed = true;
        }
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui.add(number(c).speed(0.005).range(0.0..=1.0)).labelled_by(label.id).changed();
        }
        changed
    })
    .inner
}

/// Radiance or power: unbounded above, never negative.
fn radiance_ui(ui: &mut egui::Ui, label: &str, v: &mut Vec3) -> bool {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        let mut changed = false;
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui.add(number(c).speed(0.05).range(0.0..=f32::MAX)).labelled_by(label.id).changed();
        }
        changed
    })
    .inner
}

fn properties_ui(ui: &mut egui::Ui, scene: &mut Scene, selection: &mut Selection) -> bool {
    let mut changed = false;
    match *selection {
        Selection::Camera => {
            let camera = &mut scene.camera;
            changed |= vec3_ui(ui, "Position", &mut camera.position, 0.01);
            changed |= vec3_ui(ui, "Look at", &mut camera.look_at, 0.01);
            changed |= vec3_ui(ui, "Up", &mut camera.up, 0.01);
            changed |= ui.add(slider(&mut camera.fov_y_degrees, 1.0..=170.0).text("Field of view °")).changed();
            changed |= scalar_ui(ui, "Near clip", &mut camera.near_clip, 0.0..=f32::MAX, 0.01);
            ui.horizontal(|ui| {
                ui.label("measured along");
                changed |= ui.radio_value(&mut camera.near_clip_along, ClipAlong::ViewAxis, "the view axis").changed();
                changed |= ui.radio_value(&mut camera.near_clip_along, ClipAlong::Ray, "each ray").changed();
            });
            changed |= scalar_ui(ui, "Aperture radius", &mut camera.aperture_radius, 0.0..=f32::MAX, 0.001);
            changed |= scalar_ui(ui, "Focus distance (0: look-at)", &mut camera.focus_distance, 0.0..=f32::MAX, 0.01);
            changed |= radiance_ui(ui, "Background", &mut scene.background);
            changed |= radiance_ui(ui, "Ambient (Whitted)", &mut scene.ambient);
        }
        Selection::Object(i) => {
            let names: Vec<String> = scene.materials.iter().map(|m| m.name.clone()).collect();
            let Some(object) = scene.objects.get_mut(i) else { return false };
            changed |= name_ui(ui, &mut object.name, *selection);
            egui::ComboBox::from_label("Material").selected_text(object.material.clone()).show_ui(ui, |ui| {
                for name in names {
                    changed |= ui.selectable_value(&mut object.material, name.clone(), name).changed();
                }
            });
            match &mut object.shape {
                Shape::Sphere { center, radius } => {
                    changed |= vec3_ui(ui, "Centre", center, 0.01);
                    changed |= ui
                        .horizontal(|ui| {
                            let label = ui.label("Radius");
                            let drag = number(radius).speed(0.01).range(1e-6..=f32::MAX);
                            ui.add(drag).labelled_by(label.id).changed()
                        })
                        .inner;
                }
                Shape::Plane { point, normal } => {
                    changed |= vec3_ui(ui, "Point", point, 0.01);
                    changed |= vec3_ui(ui, "Normal", normal, 0.01);
                }
                Shape::Triangle { a, b, c } => {
                    changed |= vec3_ui(ui, "A", a, 0.01);
                    changed |= vec3_ui(ui, "B", b, 0.01);
                    changed |= vec3_ui(ui, "C", c, 0.01);
                }
                Shape::Mesh { file, translate, scale, rotate_degrees } => {
                    let triangles = scene.meshes.get(file).map_or(0, |mesh| mesh.triangles.len());
                    ui.label(format!("File: {file} ({triangles} triangles)"));
                    changed |= vec3_ui(ui, "Translate", translate, 0.01);
                    changed |= scalar_ui(ui, "Scale", scale, 1e-6..=f32::MAX, 0.01);
                    changed |= vec3_ui(ui, "Rotate (°)", rotate_degrees, 0.5);
                }
            }
        }
        Selection::Material(i) => {
            let Some(material) = scene.materials.get_mut(i) else { return false };
            let old_name = material.name.clone();
            changed |= name_ui(ui, &mut material.name, *selection);
            changed |= material_model_ui(ui, &mut material.model);
            // Renaming a material keeps its objects pointing at it
            let new_name = material.name.clone();
            if new_name != old_name {
                for object in scene.objects.iter_mut().filter(|o| o.material == old_name) {
                    object.material = new_name.clone();
                }
            }
        }
        Selection::Light(i) => {
            let Some(light) = scene.lights.get_mut(i) else { return false };
            changed |= name_ui(ui, &mut light.name, *selection);
            changed |= ui.checkbox(&mut light.enabled, "Enabled").changed();
            changed |= light_kind_ui(ui, &mut light.kind);
            changed |= reflectance_ui(ui, "Colour", &mut light.color);
            changed |= scalar_ui(ui, "Intensity", &mut light.intensity, 0.0..=f32::MAX, 0.1);
            if !matches!(light.kind, LightKind::Directional { .. }) {
                let heading = ui.label("Attenuation 1/(a·d² + b·d + c)");
                ui.horizontal(|ui| {
                    let a = &mut light.attenuation;
                    for (label, v) in [("a", &mut a.a), ("b", &mut a.b), ("c", &mut a.c)] {
                        let drag = number(v).speed(0.01).range(0.0..=f32::MAX).prefix(format!("{label} "));
                        changed |= ui.add(drag).labelled_by(heading.id).changed();
                    }
                });
            }
        }
    }
    changed
}

fn name_ui(ui: &mut egui::Ui, name: &mut String, selection: Selection) -> bool {
    ui.horizontal(|ui| {
        let label = ui.label("Name");
        let edit = committed_text_ui(ui, name, selection);
        edit.response.labelled_by(label.id);
        edit.inner
    })
    .inner
}

fn material_model_ui(ui: &mut egui::Ui, model: &mut MaterialModel) -> bool {
    let (kd, ks) = match model {
        MaterialModel::Lambert { albedo } => (*albedo, Vec3::ZERO),
        MaterialModel::Phong { kd, ks, .. } | MaterialModel::BlinnPhong { kd, ks, .. } => (*kd, *ks),
        MaterialModel::Mirror { tint } | MaterialModel::Glass { tint, .. } => (*tint * 0.5, *tint * 0.5),
        MaterialModel::Emissive { radiance } => (radiance.min(Vec3::ONE), Vec3::ZERO),
        MaterialModel::Conductor { metal, .. } => (metal.normal_reflectance() * 0.5, metal.normal_reflectance() * 0.5),
    };
    let choices = [
        MaterialModel::Lambert { albedo: kd },
        MaterialModel::Phong { ka: kd, kd, ks: ks.max(Vec3::splat(0.2)).min(Vec3::ONE - kd), shininess: 30.0 },
        MaterialModel::BlinnPhong { ka: kd, kd, ks: ks.max(Vec3::splat(0.2)).min(Vec3::ONE - kd), shininess: 60.0 },
        MaterialModel::Mirror { tint: Vec3::splat(0.95) },
        MaterialModel::Glass { ior: 1.5, tint: Vec3::ONE },
        MaterialModel::Conductor { metal: Metal::Gold, alpha_u: 0.1, alpha_v: 0.1 },
        MaterialModel::Emissive { radiance: Vec3::splat(5.0) },
    ];
    let mut changed = false;
    egui::ComboBox::from_label("Model").selected_text(model.kind_name()).show_ui(ui, |ui| {
        for choice in choices {
            if ui.selectable_label(choice.kind_name() == model.kind_name(), choice.kind_name()).clicked()
                && choice.kind_name() != model.kind_name()
            {
                *model = choice;
                changed = true;
            }
        }
    });
    changed
        | match model {
            MaterialModel::Lambert { albedo } => reflectance_ui(ui, "Albedo", albedo),
            MaterialModel::Phong { ka, kd, ks, shininess } | MaterialModel::BlinnPhong { ka, kd, ks, shininess } => {
                let mut changed = reflectance_ui(ui, "ka", ka);
                changed |= reflectance_ui(ui, "kd", kd);
                changed |= reflectance_ui(ui, "ks", ks);
                let slider = slider(shininess, 0.0..=2000.0).logarithmic(true).text("Shininess");
                changed | ui.add(slider).changed()
            }
            MaterialModel::Mirror { tint } => reflectance_ui(ui, "Tint", tint),
            MaterialModel::Glass { ior, tint } => {
                let changed = ui.add(slider(ior, 1.0..=3.0).text("Index of refraction")).changed();
                changed | reflectance_ui(ui, "Tint", tint)
            }
            MaterialModel::Emissive { radiance } => radiance_ui(ui, "Radiance", radiance),
            MaterialModel::Conductor { metal, alpha_u, alpha_v } => conductor_ui(ui, metal, alpha_u, alpha_v),
        }
}

/// A metal by name or by its index, and its roughness: one slider for an
/// isotropic surface (it carries α v along while the two are equal), a
/// second for α v alone.
fn conductor_ui(ui: &mut egui::Ui, metal: &mut Metal, alpha_u: &mut f32, alpha_v: &mut f32) -> bool {
    let mut changed = false;
    egui::ComboBox::from_label("Made of").selected_text(metal.label()).show_ui(ui, |ui| {
        let (eta, k) = metal.index();
        for choice in Metal::NAMED.into_iter().chain([Metal::Custom { eta, k }]) {
            if ui.selectable_label(choice.label() == metal.label(), choice.label()).clicked()
                && choice.label() != metal.label()
            {
                *metal = choice;
                changed = true;
            }
        }
    });
    if let Metal::Custom { eta, k } = metal {
        for (label, v) in [("η", eta), ("k", k)] {
            ui.horizontal(|ui| {
                let label = ui.label(label);
                for c in [&mut v.x, &mut v.y, &mut v.z] {
                    let range = limits::METAL_INDEX.min..=limits::METAL_INDEX.max;
                    changed |= ui.add(number(c).speed(0.01).range(range)).labelled_by(label.id).changed();
                }
            });
        }
    }
    let range = limits::ROUGHNESS.min..=limits::ROUGHNESS.max;
    let isotropic = *alpha_u == *alpha_v;
    if ui.add(slider(alpha_u, range.clone()).text("Roughness α")).changed() {
        if isotropic {
            *alpha_v = *alpha_u;
        }
        changed = true;
    }
    changed | ui.add(slider(alpha_v, range).text("α v (anisotropic)")).changed()
}

fn light_kind_ui(ui: &mut egui::Ui, kind: &mut LightKind) -> bool {
    let (position, direction) = match kind {
        LightKind::Point { position } => (*position, Vec3::NEG_Y),
        LightKind::Directional { direction } => (Vec3::new(0.0, 3.0, 0.0), *direction),
        LightKind::Spot { position, direction, .. } => (*position, *direction),
    };
    let choices = [
        LightKind::Point { position },
        LightKind::Directional { direction },
        LightKind::Spot { position, direction, cone_angle_degrees: 30.0, falloff_exponent: 2.0 },
    ];
    let mut changed = false;
    egui::ComboBox::from_label("Type").selected_text(kind.kind_name()).show_ui(ui, |ui| {
        for choice in choices {
            if ui.selectable_label(choice.kind_name() == kind.kind_name(), choice.kind_name()).clicked()
                && choice.kind_name() != kind.kind_name()
            {
                *kind = choice;
                changed = true;
            }
        }
    });
    changed
        | match kind {
            LightKind::Point { position } => vec3_ui(ui, "Position", position, 0.01),
            LightKind::Directional { direction } => vec3_ui(ui, "Direction", direction, 0.01),
            LightKind::Spot { position, direction, cone_angle_degrees, falloff_exponent } => {
                let mut changed = vec3_ui(ui, "Position", position, 0.01);
                changed |= vec3_ui(ui, "Direction", direction, 0.01);
                changed |= ui.add(slider(cone_angle_degrees, 0.1..=90.0).text("Cone half-angle °")).changed();
                let falloff = slider(falloff_exponent, 0.0..=10_000.0).logarithmic(true);
                changed | ui.add(falloff.text("Falloff exponent")).changed()
            }
        }
}
