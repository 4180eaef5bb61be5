//! An A/B wipe: a pane shows another pane's image, or the reference, right
//! of a divider the user drags, the same part of the scene on both sides
//! (the shared `ImageView`), so a difference is seen where it is.

use eframe::egui;

use super::image_view::ImageView;
use crate::analysis::reference::Reference;

/// Half the width of the divider's handle, in screen points.
const HANDLE: f32 = 8.0;

/// What a wipe shows right of its divider.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Against {
    Pane(usize),
    Reference,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wipe {
    /// What is shown right of the divider.
    pub other: Against,
    /// Where the divider stands, as a fraction of the pane's width.
    pub divider: f32,
}

impl Wipe {
    pub fn new(other: Against) -> Self {
        Wipe { other, divider: 0.5 }
    }

    /// The parts of `rect` showing this pane's image and the other's.
    pub fn split(&self, rect: egui::Rect) -> (egui::Rect, egui::Rect) {
        let x = rect.min.x + self.divider.clamp(0.0, 1.0) * rect.width();
        let mut left = rect;
        left.max.x = x;
        let mut right = rect;
        right.min.x = x;
        (left, right)
    }

    /// Move the divider by `dx` screen points in a pane `width` wide.
    pub fn drag(&mut self, dx: f32, width: f32) {
        if width > 0.0 && dx.is_finite() {
            self.divider = (self.divider + dx / width).clamp(0.0, 1.0);
        }
    }
}

/// The other image right of the divider over this pane's image in `rect`,
/// the divider, and its handle, which a drag moves.
pub fn wipe_ui(
    ui: &mut egui::Ui,
    rect: egui::Rect,
    wipe: &mut Wipe,
    other: egui::TextureId,
    view: &ImageView,
    names: [String; 2],
) {
    let (_, right) = wipe.split(rect);
    ui.painter().with_clip_rect(right).image(other, rect, view.visible(), egui::Color32::WHITE);
    let x = right.min.x;
    let stroke = egui::Stroke::new(2.0, egui::Color32::WHITE);
    ui.painter().vline(x, rect.y_range(), stroke);
    let handle = egui::Rect::from_min_max(egui::pos2(x - HANDLE, rect.min.y), egui::pos2(x + HANDLE, rect.max.y));
    let response = ui.interact(handle, ui.scope_id().with("wipe"), egui::Sense::drag());
    let response = response.on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
    if response.dragged() {
        wipe.drag(response.drag_delta().x, rect.width());
    }
    let [this, that] = names;
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, format!("wipe {this} | {that}")));
    let font = egui::FontId::proportional(12.0);
    let middle = rect.center().y;
    for (text, anchor, offset) in [(this, egui::Align2::RIGHT_CENTER, -8.0), (that, egui::Align2::LEFT_CENTER, 8.0)] {
        let at = egui::pos2(x + offset, middle);
        let galley = ui.painter().layout_no_wrap(text, font.clone(), egui::Color32::WHITE);
        let placed = anchor.anchor_size(at, galley.size());
        ui.painter().rect_filled(placed.expand(3.0), 3.0, egui::Color32::from_black_alpha(160));
        ui.painter().galley(placed.min, galley, egui::Color32::WHITE);
    }
}

/// The reference tone-mapped for each pane that wipes against it (at that
/// pane's exposure), uploaded again only when the reference or the
/// exposure changed.
#[derive(Default)]
pub struct ReferenceTextures {
    /// Per pane: what the texture shows (size, samples, seconds, exposure) and it.
    shown: Vec<Option<(ReferenceKey, egui::TextureHandle)>>,
}

type ReferenceKey = (u32, u32, u32, u64, u32);

impl ReferenceTextures {
    pub fn texture(
        &mut self,
        ctx: &egui::Context,
        pane: usize,
        reference: &Reference,
        exposure: f32,
    ) -> egui::TextureId {
        let image = &reference.image;
        let info = &reference.info;
        let key = (image.width, image.height, info.samples_per_pixel, info.seconds.to_bits(), exposure.to_bits());
        if self.shown.len() <= pane {
            self.shown.resize_with(pane + 1, || None);
        }
        let slot = &mut self.shown[pane];
        if slot.as_ref().is_none_or(|(shown, _)| *shown != key) {
            let size = [image.width as usize, image.height as usize];
            let rgba = egui::ColorImage::from_rgba_unmultiplied(size, &image.to_rgba8(exposure));
            *slot = Some((key, ctx.load_texture("reference", rgba, egui::TextureOptions::LINEAR)));
        }
        slot.as_ref().map_or(egui::TextureId::default(), |(_, texture)| texture.id())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The divider splits the pane where it stands: this image left of it,
    /// the other right; a drag moves it by the dragged share of the width,
    /// never past the pane's edges.
    #[test]
    fn the_divider_decides_which_image_each_point_shows() {
        let rect = egui::Rect::from_min_size(egui::pos2(100.0, 20.0), egui::vec2(400.0, 300.0));
        let mut wipe = Wipe::new(Against::Pane(1));
        let (left, right) = wipe.split(rect);
        assert_eq!((left.max.x, right.min.x), (300.0, 300.0));
        assert_eq!(left.union(right), rect);
        wipe.drag(-100.0, rect.width());
        assert!((wipe.divider - 0.25).abs() < 1e-6);
        let (left, right) = wipe.split(rect);
        assert!(left.contains(egui::pos2(199.0, 100.0)) && right.contains(egui::pos2(201.0, 100.0)));
        wipe.drag(1e6, rect.width());
        assert_eq!(wipe.divider, 1.0);
        wipe.drag(f32::NAN, rect.width());
        assert_eq!(wipe.divider, 1.0);
        assert_eq!(wipe.split(rect).1.width(), 0.0);
    }
}
