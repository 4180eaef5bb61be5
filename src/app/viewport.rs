//! A pane's viewport: the image fitted to the pane, its label, and the
//! mouse: click picks the object under the cursor, drag orbits the camera
//! about its look-at point, shift-drag pans, scroll dollies.

use eframe::egui;
use glam::{Quat, Vec3};

use super::document::Document;
use super::inspector::Selection;
use super::pane::Pane;
use crate::scene::Camera;

/// Turn the camera about its look-at point: `yaw` about the up vector,
/// `pitch` about the camera's right vector (stopping short of the poles).
pub fn orbit(camera: &mut Camera, yaw: f32, pitch: f32) {
    let up = camera.up.normalize_or(Vec3::Y);
    let offset = camera.position - camera.look_at;
    let right = offset.cross(up).normalize_or(Vec3::X);
    let turned = Quat::from_axis_angle(up, yaw) * offset;
    let tilted = Quat::from_axis_angle(right, pitch) * turned;
    // Keep away from looking straight along `up`, where the view degenerates
    if tilted.normalize_or_zero().dot(up).abs() < 0.995 {
        camera.position = camera.look_at + tilted;
    } else {
        camera.position = camera.look_at + turned;
    }
}

/// The turn of a drag by `delta` points over an image `height` points
/// high: a drag the image's height turns by the field of view, so the
/// scene under the cursor moves with it, at any scale of scene or lens (a
/// fixed angle a point took an 80-point drag out of the Cornell box).
pub fn orbit_angles(camera: &Camera, delta: egui::Vec2, height: f32) -> (f32, f32) {
    let per_point = camera.fov_y_degrees.to_radians() / height.max(1.0);
    (-delta.x * per_point, -delta.y * per_point)
}

/// Move position and look-at together across the view.
pub fn pan(camera: &mut Camera, dx: f32, dy: f32) {
    let forward = (camera.look_at - camera.position).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(Vec3::X);
    let up = right.cross(forward);
    let distance = (camera.look_at - camera.position).length();
    let shift = (right * -dx + up * dy) * distance;
    camera.position += shift;
    camera.look_at += shift;
}

/// Move toward (factor < 1) or away from the look-at point.
pub fn dolly(camera: &mut Camera, factor: f32) {
    let offset = camera.position - camera.look_at;
    let scaled = offset * factor.clamp(0.5, 2.0);
    if scaled.length() > 1e-3 {
        camera.position = camera.look_at + scaled;
    }
}

/// Draw the pane and apply its interactions to the document's camera (a
/// change of it is an edit) and the selection.
pub fn viewport_ui(
    ui: &mut egui::Ui,
    pane: &mut Pane,
    document: &mut Document,
    selection: &mut Selection,
) -> egui::Response {
    let texture = pane.texture(ui.ctx()).clone();
    let (width, height) = (pane.state().image.width as f32, pane.state().image.height as f32);
    let available = ui.available_size();
    let scale = (available.x / width).min(available.y / height).max(0.01);
    let (rect, response) =
        ui.allocate_exact_size(egui::vec2(width * scale, height * scale), egui::Sense::click_and_drag());
    let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    ui.painter().image(texture.id(), rect, uv, egui::Color32::WHITE);
    let label = pane.label();
    // Painted over the image, and told to screen readers (and tests) too
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, &label));
    let font = egui::FontId::proportional(13.0);
    let galley = ui.painter().layout_no_wrap(label, font, egui::Color32::WHITE);
    let label_rect = egui::Rect::from_min_size(rect.min, galley.size() + egui::vec2(12.0, 6.0));
    ui.painter().rect_filled(label_rect, 3.0, egui::Color32::from_black_alpha(160));
    ui.painter().galley(rect.min + egui::vec2(6.0, 3.0), galley, egui::Color32::WHITE);
    ui.interact(label_rect, response.id.with("label"), egui::Sense::hover()).on_hover_text(
        "Seconds are the pane's own: the time its passes took on the render threads. \
         Panes take turns on the threads, fairly by time, so a pane's clock, samples per second \
         and error curve do not depend on how many panes render beside it.",
    );
    if let Some(warning) = pane.warning() {
        // Along the image's foot, wrapped to its width, and told to tests
        let text = egui::RichText::new(format!("Note: {warning}")).color(ui.visuals().warn_fg_color);
        let below = egui::Rect::from_min_max(egui::pos2(rect.min.x, rect.max.y - 60.0), rect.max).shrink(6.0);
        let mut child =
            ui.new_child(egui::UiBuilder::new().max_rect(below).layout(egui::Layout::bottom_up(egui::Align::Min)));
        egui::Frame::new().fill(egui::Color32::from_black_alpha(180)).inner_margin(4.0).show(&mut child, |ui| {
            ui.label(text);
        });
    }
    if let Some(message) = &pane.state().failed {
        ui.painter().text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            message,
            egui::FontId::proportional(14.0),
            ui.visuals().error_fg_color,
        );
    }

    let to_film = |pos: egui::Pos2| ((pos.x - rect.min.x) / scale, (pos.y - rect.min.y) / scale);
    if response.clicked() {
        if let Some(pos) = response.interact_pointer_pos() {
            let (x, y) = to_film(pos);
            match document.pick(width as u32, height as u32, x, y) {
                Some(object) => *selection = Selection::Object(object),
                None => *selection = Selection::Camera,
            }
        }
    }
    let delta = response.drag_delta();
    if response.dragged() && delta != egui::Vec2::ZERO {
        let camera = &mut document.scene_mut().camera;
        if ui.input(|i| i.modifiers.shift) {
            pan(camera, delta.x / rect.height(), delta.y / rect.height());
        } else {
            let (yaw, pitch) = orbit_angles(camera, delta, rect.height());
            orbit(camera, yaw, pitch);
        }
        document.changed();
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            dolly(&mut document.scene_mut().camera, (-scroll * 0.002).exp());
            document.changed();
        }
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::presets::default_scene;

    #[test]
    fn orbit_keeps_distance_and_dolly_changes_it() {
        let mut camera = default_scene().camera;
        let distance = (camera.position - camera.look_at).length();
        orbit(&mut camera, 0.7, 0.3);
        assert!(((camera.position - camera.look_at).length() - distance).abs() < 1e-4);
        dolly(&mut camera, 0.5);
        assert!(((camera.position - camera.look_at).length() - distance * 0.5).abs() < 1e-4);
        let look_at = camera.look_at;
        pan(&mut camera, 0.1, 0.0);
        assert!((camera.look_at - look_at).length() > 0.0);
    }

    #[test]
    fn picking_finds_the_glass_ball_in_the_cornell_box_and_nothing_in_a_broken_scene() {
        let scene = default_scene();
        let camera = crate::render::world::camera::CameraModel::new(&scene.camera, 160, 120);
        let ball = scene.objects.iter().position(|o| o.name == "glass ball").unwrap();
        let p = camera.project(glam::Vec3::new(0.45, 0.35, 0.2)).unwrap();
        let mut document = Document::new(scene, None, true);
        assert_eq!(document.pick(160, 120, p.x, p.y), Some(ball));
        document.scene_mut().objects[ball].material = "nowhere".into();
        document.changed();
        document.check();
        assert_eq!(document.pick(160, 120, p.x, p.y), None);
    }
}
