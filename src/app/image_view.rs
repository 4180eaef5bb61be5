//! How the panes show their images, apart from the camera: a zoom and a
//! pan shared by every pane (linked, so a detail is seen in every
//! algorithm's image at once), and the point under the pointer, which every
//! pane reads out. Positions are in image fractions (0 to 1 across and
//! down), so panes of different sizes show the same part of the scene.

use eframe::egui::{pos2, vec2, Pos2, Rect, Vec2};

/// The closest look: a pixel of a 64-pixel-wide image fills most of a pane.
pub const MAX_ZOOM: f32 = 256.0;

/// Screen points per image pixel from which pixels are drawn as squares
/// (nearest neighbour) instead of blended.
pub const NEAREST_FROM: f32 = 4.0;

/// Screen points per image pixel from which the pixel grid is drawn.
pub const GRID_FROM: f32 = 16.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageView {
    /// 1: the whole image fits its pane; 2: half of it across, and so on.
    zoom: f32,
    /// The image point at the middle of each pane.
    center: Vec2,
    /// The image point under the pointer, in whichever pane it is.
    pub hovered: Option<Vec2>,
}

impl Default for ImageView {
    fn default() -> Self {
        ImageView { zoom: 1.0, center: vec2(0.5, 0.5), hovered: None }
    }
}

impl ImageView {
    pub fn zoom(&self) -> f32 {
        self.zoom
    }

    /// Whether the whole image is shown.
    pub fn fits(&self) -> bool {
        self.zoom == 1.0
    }

    /// Back to the whole image.
    pub fn fit(&mut self) {
        *self = ImageView { hovered: self.hovered, ..ImageView::default() };
    }

    /// The part of the image shown, in image fractions (a texture's uv).
    pub fn visible(&self) -> Rect {
        Rect::from_center_size(self.center.to_pos2(), Vec2::splat(1.0 / self.zoom))
    }

    /// The image point drawn at `pos` of a pane drawn in `rect`.
    pub fn image_point(&self, rect: Rect, pos: Pos2) -> Vec2 {
        let visible = self.visible();
        let across = (pos - rect.min) / rect.size();
        visible.min.to_vec2() + across * visible.size()
    }

    /// Zoom by `factor` about the image point `fixed`, which stays where it
    /// is drawn; the view stays inside the image.
    pub fn zoom_about(&mut self, factor: f32, fixed: Vec2) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let zoom = (self.zoom * factor).clamp(1.0, MAX_ZOOM);
        // The fixed point's offset from the centre shrinks with the view
        self.center = fixed + (self.center - fixed) * (self.zoom / zoom);
        self.zoom = zoom;
        self.keep_inside();
    }

    /// Move the view by `delta` screen points in a pane drawn in `rect`
    /// (dragging the image: it follows the pointer).
    pub fn pan(&mut self, delta: Vec2, rect: Rect) {
        if rect.width() > 0.0 && rect.height() > 0.0 {
            self.center -= delta / rect.size() / self.zoom;
            self.keep_inside();
        }
    }

    fn keep_inside(&mut self) {
        let half = 0.5 / self.zoom;
        self.center = vec2(self.center.x.clamp(half, 1.0 - half), self.center.y.clamp(half, 1.0 - half));
    }

    /// The pixel at image point `point` of a `width × height` image.
    pub fn pixel(point: Vec2, width: u32, height: u32) -> Option<(u32, u32)> {
        let (x, y) = (point.x * width as f32, point.y * height as f32);
        let inside = (0.0..width as f32).contains(&x) && (0.0..height as f32).contains(&y);
        inside.then_some((x as u32, y as u32))
    }

    /// Screen points a pixel of a `width`-pixel-wide image takes in a pane
    /// drawn `rect_width` wide.
    pub fn pixel_size(&self, rect_width: f32, width: u32) -> f32 {
        rect_width * self.zoom / width.max(1) as f32
    }

    /// Where the edges of the visible pixels of a `width × height` image lie
    /// on screen in `rect`: the columns' x and the rows' y.
    pub fn grid(&self, rect: Rect, width: u32, height: u32) -> (Vec<f32>, Vec<f32>) {
        let visible = self.visible();
        let edges = |from: f32, to: f32, count: u32, start: f32, length: f32| -> Vec<f32> {
            let (first, last) = ((from * count as f32).ceil() as u32, (to * count as f32).floor() as u32);
            (first..=last.min(count)).map(|i| start + (i as f32 / count as f32 - from) / (to - from) * length).collect()
        };
        (
            edges(visible.min.x, visible.max.x, width, rect.min.x, rect.width()),
            edges(visible.min.y, visible.max.y, height, rect.min.y, rect.height()),
        )
    }
}

/// The screen point of image point `point` in a pane drawn in `rect`.
pub fn screen_point(view: &ImageView, rect: Rect, point: Vec2) -> Pos2 {
    let visible = view.visible();
    let across = (point - visible.min.to_vec2()) / visible.size();
    pos2(rect.min.x + across.x * rect.width(), rect.min.y + across.y * rect.height())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pane() -> Rect {
        Rect::from_min_size(pos2(100.0, 50.0), vec2(400.0, 300.0))
    }

    /// Zooming about the pointer keeps the image point under it where it
    /// was drawn, at every step, in and out, wherever the pointer is.
    #[test]
    fn the_point_under_the_pointer_stays_put_while_zooming() {
        let rect = pane();
        let mut view = ImageView::default();
        for (pos, factor) in [(pos2(430.0, 80.0), 2.0), (pos2(430.0, 80.0), 3.0), (pos2(200.0, 300.0), 1.5)] {
            let point = view.image_point(rect, pos);
            let before = screen_point(&view, rect, point);
            view.zoom_about(factor, point);
            let after = screen_point(&view, rect, point);
            // Near the image's edge the view stops at the edge instead
            let visible = view.visible();
            let clamped = visible.min.x <= 1e-6
                || visible.min.y <= 1e-6
                || visible.max.x >= 1.0 - 1e-6
                || visible.max.y >= 1.0 - 1e-6;
            if !clamped {
                assert!((after - before).length() < 1e-3, "{before:?} moved to {after:?} zooming by {factor}");
            }
            assert!(view.visible().min.x >= -1e-6 && view.visible().max.x <= 1.0 + 1e-6, "{view:?} leaves the image");
        }
        assert!((view.zoom() - 9.0).abs() < 1e-4, "{}", view.zoom());
    }

    #[test]
    fn zoom_is_bounded_and_fit_shows_the_whole_image() {
        let mut view = ImageView::default();
        view.zoom_about(0.25, vec2(0.3, 0.3));
        assert!(view.fits(), "zooming out past the whole image: {view:?}");
        assert_eq!(view.visible(), Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)));
        for _ in 0..20 {
            view.zoom_about(4.0, vec2(0.9, 0.1));
        }
        assert_eq!(view.zoom(), MAX_ZOOM);
        view.zoom_about(f32::NAN, vec2(0.5, 0.5));
        view.zoom_about(f32::INFINITY, vec2(0.5, 0.5));
        assert_eq!(view.zoom(), MAX_ZOOM);
        view.fit();
        assert!(view.fits());
        assert_eq!(view.visible(), Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)));
    }

    /// Dragging moves the image with the pointer until its edge.
    #[test]
    fn panning_follows_the_pointer_and_stops_at_the_edge() {
        let rect = pane();
        let mut view = ImageView::default();
        view.zoom_about(4.0, vec2(0.5, 0.5));
        let point = view.image_point(rect, pos2(300.0, 200.0));
        view.pan(vec2(-40.0, 30.0), rect);
        let moved = screen_point(&view, rect, point);
        assert!((moved - pos2(260.0, 230.0)).length() < 1e-3, "{moved:?}");
        view.pan(vec2(1e6, 1e6), rect);
        assert!(view.visible().min.x.abs() < 1e-6 && view.visible().min.y.abs() < 1e-6, "{view:?}");
    }

    /// The pixel under an image point, and the grid's lines at the visible
    /// pixels' edges: at 8× on a 64 × 48 image, 8 × 6 pixels show, their
    /// edges 9 × 7 lines a pixel's width apart.
    #[test]
    fn pixels_and_their_grid() {
        assert_eq!(ImageView::pixel(vec2(0.0, 0.0), 64, 48), Some((0, 0)));
        assert_eq!(ImageView::pixel(vec2(0.999, 0.5), 64, 48), Some((63, 24)));
        assert_eq!(ImageView::pixel(vec2(1.0, 0.5), 64, 48), None);
        assert_eq!(ImageView::pixel(vec2(-0.01, 0.5), 64, 48), None);
        let rect = Rect::from_min_size(pos2(0.0, 0.0), vec2(640.0, 480.0));
        let mut view = ImageView::default();
        view.zoom_about(8.0, vec2(0.5, 0.5));
        assert_eq!(view.pixel_size(rect.width(), 64), 80.0);
        let (columns, rows) = view.grid(rect, 64, 48);
        assert_eq!((columns.len(), rows.len()), (9, 7));
        for pair in columns.windows(2).chain(rows.windows(2)) {
            assert!((pair[1] - pair[0] - 80.0).abs() < 1e-2, "{pair:?}");
        }
        assert!(columns[0].abs() < 1e-2 && (columns[8] - 640.0).abs() < 1e-2, "{columns:?}");
    }
}
