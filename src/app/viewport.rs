//! A pane's viewport: the image fitted to the pane (or the part of it the
//! shared `ImageView` shows), its label, the read-out under the pointer,
//! and the mouse: click picks the object under the cursor, drag orbits the
//! camera about its look-at point, shift-drag pans, scroll dollies; with
//! Ctrl (⌘) the wheel zooms the images and a drag pans them.

use eframe::egui;
use glam::{Quat, Vec3};

use super::document::Document;
use super::handles::light_handles_ui;
use super::image_view::{screen_point, ImageView, GRID_FROM, NEAREST_FROM};
use super::inspector::Selection;
use super::outline::{outline_ui, Outline};
use super::pane::Pane;
use super::readout::{readout_ui, Readout};
use super::wipe::{wipe_ui, Wipe};
use crate::render::image::LinearImage;
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

/// How a pane is looked at: the panes' shared view; the image point whose
/// values every pane reads out (the point under the pointer here goes into
/// `view.hovered`); the reference; another pane's image wiped over this
/// one (its texture and both panes' names).
pub struct Look<'a> {
    pub view: &'a mut ImageView,
    pub shown: Option<egui::Vec2>,
    pub reference: Option<&'a LinearImage>,
    pub wipe: Option<(&'a mut Wipe, egui::TextureId, [String; 2])>,
    /// The selected object's outline in this pane.
    pub outline: &'a Outline,
}

/// Draw the pane and apply its interactions: to the document's camera (a
/// change of it is an edit) and the selection, or with Ctrl (⌘) held to the
/// panes' shared view (the wheel zooms about the pointer, a drag pans).
pub fn viewport_ui(
    ui: &mut egui::Ui,
    pane: &mut Pane,
    document: &mut Document,
    selection: &mut Selection,
    look: Look<'_>,
) -> egui::Response {
    let Look { view, shown, reference, wipe, outline } = look;
    let (width, height) = (pane.state().image.width, pane.state().image.height);
    let available = ui.available_size();
    let scale = (available.x / width as f32).min(available.y / height as f32).max(0.01);
    let (rect, response) =
        ui.allocate_exact_size(egui::vec2(width as f32 * scale, height as f32 * scale), egui::Sense::click_and_drag());
    let pixel_size = view.pixel_size(rect.width(), width);
    let texture = pane.texture(ui.ctx(), pixel_size >= NEAREST_FROM).clone();
    ui.painter().image(texture.id(), rect, view.visible(), egui::Color32::WHITE);
    if pixel_size >= GRID_FROM {
        pixel_grid_ui(ui, rect, view, width, height);
    }
    if let Some((wipe, other, names)) = wipe {
        wipe_ui(ui, rect, wipe, other, view, names);
    }
    outline_ui(ui, rect, view, outline);
    light_handles_ui(ui, rect, view, (width, height), document, selection);
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
    let pixel = shown.and_then(|point| ImageView::pixel(point, width, height));
    if let Some(readout) = pixel.and_then(|pixel| Readout::of(&pane.state().image, pixel, reference)) {
        if pixel_size >= NEAREST_FROM {
            let (x, y) = readout.pixel;
            let corner = |x: u32, y: u32| {
                screen_point(view, rect, egui::vec2(x as f32 / width as f32, y as f32 / height as f32))
            };
            let outline = egui::Rect::from_min_max(corner(x, y), corner(x + 1, y + 1));
            ui.painter().with_clip_rect(rect).rect_stroke(
                outline,
                0.0,
                egui::Stroke::new(1.5, egui::Color32::YELLOW),
                egui::StrokeKind::Middle,
            );
        }
        readout_ui(ui, rect, &readout);
    }

    let to_film = |pos: egui::Pos2| {
        let point = view.image_point(rect, pos);
        (point.x * width as f32, point.y * height as f32)
    };
    if response.clicked() {
        if let Some(pos) = response.interact_pointer_pos() {
            let (x, y) = to_film(pos);
            match document.pick(width, height, x, y) {
                Some(object) => *selection = Selection::Object(object),
                None => *selection = Selection::Camera,
            }
        }
    }
    let looking = ui.input(|i| i.modifiers.command);
    let delta = response.drag_delta();
    if response.dragged() && delta != egui::Vec2::ZERO {
        if looking {
            view.pan(delta, rect);
        } else {
            let camera = &mut document.scene_mut().camera;
            if ui.input(|i| i.modifiers.shift) {
                pan(camera, delta.x / rect.height(), delta.y / rect.height());
            } else {
                let (yaw, pitch) = orbit_angles(camera, delta, rect.height());
                orbit(camera, yaw, pitch);
            }
            document.changed();
        }
    }
    if let Some(pos) = response.hover_pos() {
        let point = view.image_point(rect, pos);
        view.hovered = Some(point);
        // Ctrl (⌘) with the wheel, or a pinch, zooms the images
        let zoom = ui.input(|i| i.zoom_delta());
        if zoom != 1.0 {
            view.zoom_about(zoom, point);
        }
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 && !looking {
            dolly(&mut document.scene_mut().camera, (-scroll * 0.002).exp());
            document.changed();
        }
    }
    response
}

/// Lines at the edges of the pixels shown, when each is large on screen.
fn pixel_grid_ui(ui: &egui::Ui, rect: egui::Rect, view: &ImageView, width: u32, height: u32) {
    let painter = ui.painter().with_clip_rect(rect);
    let stroke = egui::Stroke::new(1.0, egui::Color32::from_black_alpha(90));
    let (columns, rows) = view.grid(rect, width, height);
    for x in columns {
        painter.vline(x, rect.y_range(), stroke);
    }
    for y in rows {
        painter.hline(rect.x_range(), y, stroke);
    }
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
