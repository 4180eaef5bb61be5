//! The values under the pointer: in every pane, the pixel's linear RGB,
//! the reference's value there and the pixel's squared relative error
//! (v − r)²/(r² + ε), the term relMSE averages (the pane's figure divides
//! by a reference smoothed within its noise, and takes off its noise).

use eframe::egui;

use crate::render::film::REL_MSE_EPSILON;
use crate::render::image::LinearImage;

/// What one pane reads at one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Readout {
    pub pixel: (u32, u32),
    pub value: [f32; 3],
    /// The reference's value over the same area, where there is a
    /// reference at this size or a whole multiple of it, or a whole
    /// fraction of it (then over the block of `block` × `block` pixels the
    /// reference's pixel covers).
    pub reference: Option<[f32; 3]>,
    /// What is compared with the reference: the value, or the block's mean
    /// where the reference is smaller (as the pane's error is measured).
    pub compared: [f32; 3],
    pub block: u32,
}

impl Readout {
    /// Pixel `pixel` of `image`, against `reference` if given.
    pub fn of(image: &LinearImage, pixel: (u32, u32), reference: Option<&LinearImage>) -> Option<Self> {
        let (x, y) = pixel;
        if x >= image.width || y >= image.height {
            return None;
        }
        let value = image.get(x, y);
        let mut readout = Readout { pixel, value, reference: None, compared: value, block: 1 };
        let Some(reference) = reference else { return Some(readout) };
        if let Some(mean) = area_mean(reference, image.width, image.height, pixel) {
            readout.reference = Some(mean);
        } else {
            // A reference smaller by a whole factor: the pane is measured
            // box-filtered to its size, so this pixel counts in its block
            let block = image.width / reference.width.max(1);
            if let Some(mean) =
                area_mean(image, reference.width, reference.height, (x / block.max(1), y / block.max(1)))
            {
                readout.reference = Some(reference.get(x / block, y / block));
                (readout.compared, readout.block) = (mean, block);
            }
        }
        Some(readout)
    }

    /// (v − r)² / (r² + ε) averaged over the channels.
    pub fn relative_error(&self) -> Option<f64> {
        let reference = self.reference?;
        let term = |c: usize| {
            let (v, r) = (self.compared[c] as f64, reference[c] as f64);
            (v - r).powi(2) / (r * r + REL_MSE_EPSILON)
        };
        Some((term(0) + term(1) + term(2)) / 3.0)
    }

    pub fn text(&self) -> String {
        let rgb = |c: [f32; 3]| format!("{:.4} {:.4} {:.4}", c[0], c[1], c[2]);
        let mut text = format!("pixel ({}, {})\nRGB {}", self.pixel.0, self.pixel.1, rgb(self.value));
        match (self.reference, self.relative_error()) {
            (Some(reference), Some(error)) if self.block > 1 => {
                let (block, mean) = (self.block, rgb(self.compared));
                text +=
                    &format!("\n{block}×{block} mean {mean}\nreference {}\nrel. error² {error:.2e}", rgb(reference));
            }
            (Some(reference), Some(error)) => {
                text += &format!("\nreference {}\nrel. error² {error:.2e}", rgb(reference));
            }
            _ => text += "\nno reference at this size",
        }
        text
    }
}

/// The mean of `image` over the area pixel `pixel` of a `width × height`
/// image covers, where `image` is that size or a whole multiple of it (the
/// box filter the panes' error uses).
fn area_mean(image: &LinearImage, width: u32, height: u32, (x, y): (u32, u32)) -> Option<[f32; 3]> {
    let factor = image.width / width.max(1);
    if factor == 0 || image.width != width * factor || image.height != height * factor {
        return None;
    }
    Some(image.block_mean(x, y, factor))
}

/// The read-out drawn over the bottom right of a pane's image in `rect`
/// (the pane's label is at the top), in a small type and unwrapped, so it
/// keeps to a corner of a small pane.
pub fn readout_ui(ui: &mut egui::Ui, rect: egui::Rect, readout: &Readout) {
    let text = egui::RichText::new(readout.text()).monospace().size(10.5).color(egui::Color32::WHITE);
    let layout = egui::Layout::bottom_up(egui::Align::Max);
    let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect.shrink(4.0)).layout(layout));
    egui::Frame::new().fill(egui::Color32::from_black_alpha(180)).inner_margin(3.0).show(&mut child, |ui| {
        ui.add(egui::Label::new(text).selectable(false).extend());
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(width: u32, height: u32) -> LinearImage {
        let mut image = LinearImage::new(width, height);
        for y in 0..height {
            for x in 0..width {
                image.pixels[(y * width + x) as usize] = [x as f32, y as f32, (x * y) as f32 * 0.5];
            }
        }
        image
    }

    /// A reference twice or three times the pane's size is read as the mean
    /// over the pixel's area, what `LinearImage::downsample` makes of it; a
    /// reference of another size gives no value.
    #[test]
    fn the_reference_is_read_over_the_pixels_area() {
        let pane = ramp(8, 6);
        for factor in [1, 2, 3] {
            let reference = ramp(8 * factor, 6 * factor);
            let filtered = reference.downsample(factor);
            for (x, y) in [(0, 0), (7, 5), (3, 2)] {
                let readout = Readout::of(&pane, (x, y), Some(&reference)).expect("inside");
                assert_eq!(readout.reference, Some(filtered.get(x, y)), "×{factor} at ({x}, {y})");
                assert_eq!(readout.value, pane.get(x, y));
            }
        }
        let odd = ramp(12, 9);
        assert_eq!(Readout::of(&pane, (1, 1), Some(&odd)).and_then(|r| r.reference), None);
        // A reference half the size: its pixel, against the pane's 2 × 2 block
        let small = ramp(4, 3);
        let readout = Readout::of(&pane, (5, 3), Some(&small)).expect("inside");
        assert_eq!(readout.reference, Some(small.get(2, 1)));
        assert_eq!((readout.compared, readout.block), (pane.downsample(2).get(2, 1), 2));
        assert_eq!(readout.value, pane.get(5, 3));
        assert_eq!(Readout::of(&pane, (8, 0), None), None);
    }

    /// The error is the pixel's relMSE term: zero on the reference, and
    /// (v − r)²/(r² + ε) per channel otherwise.
    #[test]
    fn the_relative_error_is_the_relmse_term() {
        let at = |value: [f32; 3], reference| Readout { pixel: (0, 0), value, reference, compared: value, block: 1 };
        let exact = at([0.5, 1.0, 2.0], Some([0.5, 1.0, 2.0]));
        assert_eq!(exact.relative_error(), Some(0.0));
        let off = at([1.0, 1.0, 1.0], Some([0.5, 1.0, 0.0]));
        let expected = (0.25 / (0.25 + REL_MSE_EPSILON) + 1.0 / REL_MSE_EPSILON) / 3.0;
        assert!((off.relative_error().unwrap() - expected).abs() < 1e-9 * expected);
        let alone = Readout { reference: None, ..off };
        assert_eq!(alone.relative_error(), None);
        assert!(alone.text().contains("no reference"), "{}", alone.text());
        assert!(off.text().contains("reference 0.5000 1.0000 0.0000"), "{}", off.text());
    }
}
