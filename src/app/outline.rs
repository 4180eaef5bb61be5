//! The selected object outlined in every pane: which pixels see it, found by
//! the same picking a click uses, worked out again only when the scene, the
//! selection or the pane's size changes, and drawn as the edges between
//! its pixels and the others.

use std::sync::Arc;

use eframe::egui;

use super::document::Document;
use super::image_view::{screen_point, ImageView};
use crate::scene::ValidScene;

/// The widest mask worked out: a larger image is sampled every few pixels,
/// so a change costs at most this many rays a row.
const MASK_WIDTH: u32 = 200;

/// One pane's outline and what it was worked out for.
#[derive(Clone, Default)]
pub struct Outline {
    /// The scene (a new snapshot each valid edit, held so that its address
    /// is not reused), the object and the image size.
    key: Option<(Arc<ValidScene>, usize, u32, u32)>,
    /// Edges between the object's pixels and the others, in image fractions.
    edges: Vec<[egui::Vec2; 2]>,
}

impl Outline {
    /// Whether it is up to date for `object` in a `width × height` image
    /// of the document's scene.
    pub fn is_for(&self, document: &Document, object: Option<usize>, width: u32, height: u32) -> bool {
        match (&self.key, object.zip(document.valid())) {
            (Some((shown, o, w, h)), Some((object, scene))) => {
                Arc::ptr_eq(shown, scene) && (*o, *w, *h) == (object, width, height)
            }
            // Nothing to outline, and nothing outlined
            (None, None) => true,
            _ => false,
        }
    }

    /// Up to date for `object` (None: nothing selected) in a `width × height` image.
    pub fn update(&mut self, document: &Document, object: Option<usize>, width: u32, height: u32) {
        let (Some(object), Some(scene)) = (object, document.valid()) else {
            self.key = None;
            self.edges.clear();
            return;
        };
        if self.is_for(document, Some(object), width, height) {
            return;
        }
        self.key = Some((scene.clone(), object, width, height));
        let step = width.div_ceil(MASK_WIDTH).max(1);
        let (mask_width, mask_height) = (width.div_ceil(step), height.div_ceil(step));
        let mut mask = vec![false; (mask_width * mask_height) as usize];
        for y in 0..mask_height {
            for x in 0..mask_width {
                let (fx, fy) =
                    (((x * step) as f32 + 0.5).min(width as f32), ((y * step) as f32 + 0.5).min(height as f32));
                mask[(y * mask_width + x) as usize] = document.pick(width, height, fx, fy) == Some(object);
            }
        }
        self.edges = edges(&mask, mask_width, mask_height);
    }

    pub fn edges(&self) -> &[[egui::Vec2; 2]] {
        &self.edges
    }
}

/// The edges between set and unset cells of a `width × height` mask (the
/// image's border counting as unset), in fractions of the mask.
fn edges(mask: &[bool], width: u32, height: u32) -> Vec<[egui::Vec2; 2]> {
    let set = |x: i64, y: i64| {
        (0..width as i64).contains(&x) && (0..height as i64).contains(&y) && mask[(y * width as i64 + x) as usize]
    };
    let at = |x: i64, y: i64| egui::vec2(x as f32 / width as f32, y as f32 / height as f32);
    let mut edges = Vec::new();
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            if !set(x, y) {
                continue;
            }
            if !set(x - 1, y) {
                edges.push([at(x, y), at(x, y + 1)]);
            }
            if !set(x + 1, y) {
                edges.push([at(x + 1, y), at(x + 1, y + 1)]);
            }
            if !set(x, y - 1) {
                edges.push([at(x, y), at(x + 1, y)]);
            }
            if !set(x, y + 1) {
                edges.push([at(x, y + 1), at(x + 1, y + 1)]);
            }
        }
    }
    edges
}

/// The outline over a pane's image in `rect`, as `view` shows it.
pub fn outline_ui(ui: &egui::Ui, rect: egui::Rect, view: &ImageView, outline: &Outline) {
    let painter = ui.painter().with_clip_rect(rect);
    let stroke = egui::Stroke::new(2.0, egui::Color32::from_rgb(255, 160, 40));
    for [a, b] in outline.edges() {
        painter.line_segment([screen_point(view, rect, *a), screen_point(view, rect, *b)], stroke);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 block inside a 4 × 3 mask has eight edges, one a side of each
    /// of its cells that faces out; a block at the border is closed by it.
    #[test]
    fn the_outline_is_the_edges_facing_out() {
        let mut mask = vec![false; 12];
        for (x, y) in [(1, 0), (2, 0), (1, 1), (2, 1)] {
            mask[y * 4 + x] = true;
        }
        let found = edges(&mask, 4, 3);
        assert_eq!(found.len(), 8);
        let (xs, ys): (Vec<f32>, Vec<f32>) = found.iter().flatten().map(|p| (p.x * 4.0, p.y * 3.0)).unzip();
        let span = |v: &[f32]| (v.iter().copied().fold(f32::MAX, f32::min), v.iter().copied().fold(f32::MIN, f32::max));
        assert_eq!((span(&xs), span(&ys)), ((1.0, 3.0), (0.0, 2.0)));
        // Every edge is one cell long and lies on the block's boundary
        for [a, b] in &found {
            assert!(((*b - *a) * egui::vec2(4.0, 3.0)).length() == 1.0, "{a:?} {b:?}");
        }
        assert!(edges(&[false; 12], 4, 3).is_empty());
        assert_eq!(edges(&[true; 12], 4, 3).len(), 2 * (4 + 3));
    }
}
