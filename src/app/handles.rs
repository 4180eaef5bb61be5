//! Lights with a position (point and spot lights) drawn as small handles
//! over a pane's image: a click selects one, a drag moves it parallel to
//! the image, at its depth, so it stays under the pointer (one undo step a
//! drag, as every drag is).

use eframe::egui;
use glam::Vec3;

use super::document::Document;
use super::image_view::{screen_point, ImageView};
use super::inspector::Selection;
use crate::render::world::camera::CameraModel;
use crate::scene::{Camera, LightKind};

/// A handle's radius in screen points.
const RADIUS: f32 = 6.0;

/// The world displacement of a point at `point` that keeps it under a
/// pointer moved by `delta` screen points, the view `height` points high
/// showing `1 / zoom` of the image.
pub fn drag_in_view(camera: &Camera, point: Vec3, delta: egui::Vec2, height: f32, zoom: f32) -> Vec3 {
    let forward = (camera.look_at - camera.position).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(Vec3::X);
    let up = right.cross(forward);
    let depth = (point - camera.position).dot(forward).max(1e-3);
    let per_point = 2.0 * depth * (camera.fov_y_degrees.to_radians() * 0.5).tan() / (height.max(1.0) * zoom);
    (right * delta.x - up * delta.y) * per_point
}

fn position(kind: &LightKind) -> Option<Vec3> {
    match *kind {
        LightKind::Point { position } | LightKind::Spot { position, .. } => Some(position),
        LightKind::Directional { .. } => None,
    }
}

fn position_mut(kind: &mut LightKind) -> Option<&mut Vec3> {
    match kind {
        LightKind::Point { position } | LightKind::Spot { position, .. } => Some(position),
        LightKind::Directional { .. } => None,
    }
}

/// The handles over a `width × height` pane image drawn in `rect`.
pub fn light_handles_ui(
    ui: &mut egui::Ui,
    rect: egui::Rect,
    view: &ImageView,
    (width, height): (u32, u32),
    document: &mut Document,
    selection: &mut Selection,
) {
    let camera = CameraModel::new(&document.scene().camera, width, height);
    let seen: Vec<(usize, Vec3, egui::Pos2)> = (document.scene().lights.iter().enumerate())
        .filter_map(|(i, light)| {
            let point = position(&light.kind)?;
            let film = camera.project(point)?;
            let fraction = egui::vec2(film.x / width as f32, film.y / height as f32);
            Some((i, point, screen_point(view, rect, fraction)))
        })
        .filter(|(_, _, at)| rect.contains(*at))
        .collect();
    for (i, point, at) in seen {
        let name = &document.scene().lights[i].name;
        let id = ui.scope_id().with(("light handle", i));
        let area = egui::Rect::from_center_size(at, egui::Vec2::splat(2.0 * RADIUS + 4.0));
        let response = ui.interact(area, id, egui::Sense::click_and_drag());
        let label = format!("light {name}");
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Button, true, &label));
        let selected = *selection == Selection::Light(i);
        let fill =
            if selected { egui::Color32::from_rgb(255, 160, 40) } else { egui::Color32::from_rgb(255, 230, 120) };
        ui.painter().circle(at, RADIUS, fill, egui::Stroke::new(1.5, egui::Color32::BLACK));
        if response.clicked() || response.drag_started() {
            *selection = Selection::Light(i);
        }
        let delta = response.drag_delta();
        if response.dragged() && delta != egui::Vec2::ZERO {
            let shift = drag_in_view(&document.scene().camera, point, delta, rect.height(), view.zoom());
            if let Some(position) = position_mut(&mut document.scene_mut().lights[i].kind) {
                *position += shift;
                document.changed();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point moved by `drag_in_view` lands where the pointer went: its
    /// projection moves by the drag (in film pixels, the view the film's
    /// size), at any depth and zoom 1.
    #[test]
    fn a_dragged_light_stays_under_the_pointer() {
        let camera = Camera {
            position: Vec3::new(0.0, 1.0, 3.4),
            look_at: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_degrees: 40.0,
            near_clip: 0.0,
            near_clip_along: Default::default(),
            aperture_radius: 0.0,
            focus_distance: 0.0,
        };
        let model = CameraModel::new(&camera, 320, 240);
        for point in [Vec3::new(0.2, 1.5, 0.0), Vec3::new(-0.4, 0.7, -1.0), Vec3::new(0.1, 1.2, 2.0)] {
            let before = model.project(point).expect("in view");
            let delta = egui::vec2(25.0, -12.0);
            let moved = point + drag_in_view(&camera, point, delta, 240.0, 1.0);
            let after = model.project(moved).expect("in view");
            let went = after - before;
            assert!((went.x - 25.0).abs() < 0.05 && (went.y + 12.0).abs() < 0.05, "{point}: moved {went}");
        }
    }
}
