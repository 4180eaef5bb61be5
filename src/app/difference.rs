//! The difference view: where any pane disagrees with the reference (at
//! the reference's size) or with another pane of its size, as relative
//! error or as signed difference in false colour with its scale, refreshed
//! twice a second, kept inside the panes' area.

use std::borrow::Cow;
use std::time::Instant;

use eframe::egui;

use super::export::difference_rgba;
use super::panes::Panes;
use super::wipe::Against;
use crate::analysis::metrics::false_colour;
use crate::analysis::reference::Reference;
use crate::render::image::LinearImage;

/// What the view shows of two images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// (a − b)² / (b² + ε) per pixel, 0 to the 99th percentile.
    RelativeError,
    /// a − b in luminance, blue below, red above, symmetric about 0.
    Signed,
}

pub struct Difference {
    /// The pane compared.
    pane: usize,
    against: Against,
    metric: Metric,
    texture: Option<egui::TextureHandle>,
    /// The colour scale's top (|a − b| for the signed metric).
    top: Option<f64>,
    at: Option<Instant>,
}

impl Default for Difference {
    fn default() -> Self {
        Difference {
            pane: 0,
            against: Against::Reference,
            metric: Metric::RelativeError,
            texture: None,
            top: None,
            at: None,
        }
    }
}

impl Difference {
    pub fn difference_ui(&mut self, ctx: &egui::Context, panes: &Panes, reference: Option<&Reference>) {
        let count = panes.list().len();
        self.pane = self.pane.min(count.saturating_sub(1));
        if matches!(self.against, Against::Pane(other) if other >= count || other == self.pane) {
            self.against = Against::Reference;
        }
        let refresh = self.at.is_none_or(|t| t.elapsed().as_secs_f32() > 0.5);
        let compared = self.compared(panes, reference);
        let caption = match &compared {
            Some(_) => self.label(),
            None => match self.against {
                Against::Reference => "no reference at this pane's size or a whole fraction of it".to_owned(),
                Against::Pane(_) => "the two panes differ in size".to_owned(),
            },
        };
        if refresh {
            self.at = Some(Instant::now());
            let drawn = compared.and_then(|(a, b)| match self.metric {
                Metric::RelativeError => difference_rgba(&a, b).map(|(rgba, top)| (rgba, top, a.width, a.height)),
                Metric::Signed => signed_rgba(&a, b).map(|(rgba, top)| (rgba, top, a.width, a.height)),
            });
            (self.texture, self.top) = match drawn {
                Some((rgba, top, width, height)) => {
                    let image = egui::ColorImage::from_rgba_unmultiplied([width as usize, height as usize], &rgba);
                    (Some(ctx.load_texture("difference", image, egui::TextureOptions::NEAREST)), Some(top))
                }
                None => (None, None),
            };
        }
        let window = egui::Window::new("Difference").default_size([380.0, 340.0]).constrain_to(panes.area());
        window.show(ctx, |ui| {
            let before = (self.pane, self.against, self.metric);
            self.choices_ui(ui, count);
            if (self.pane, self.against, self.metric) != before {
                self.at = None;
            }
            ui.label(&caption);
            if let (Some(texture), Some(top)) = (&self.texture, self.top) {
                let size = texture.size_vec2();
                let scale = (ui.available_width() / size.x).min(2.0);
                ui.image((texture.id(), size * scale));
                scale_ui(ui, self.metric, top, size.x * scale);
            }
        });
        ctx.request_repaint_after(std::time::Duration::from_millis(500));
    }

    fn label(&self) -> String {
        let against = match self.against {
            Against::Reference => "the reference".to_owned(),
            Against::Pane(other) => format!("pane {}", other + 1),
        };
        format!("pane {} against {against}", self.pane + 1)
    }

    /// The two images compared, at one size.
    fn compared<'a>(
        &self,
        panes: &'a Panes,
        reference: Option<&'a Reference>,
    ) -> Option<(Cow<'a, LinearImage>, &'a LinearImage)> {
        let image = &panes.list().get(self.pane)?.state().image;
        match self.against {
            Against::Reference => {
                let reference = &reference?.image;
                Some((image.at_size(reference.width, reference.height)?, reference))
            }
            Against::Pane(other) => {
                let other = &panes.list().get(other)?.state().image;
                ((other.width, other.height) == (image.width, image.height)).then_some((Cow::Borrowed(image), other))
            }
        }
    }

    /// "[pane k] against [image] as (metric)".
    fn choices_ui(&mut self, ui: &mut egui::Ui, count: usize) {
        ui.horizontal_wrapped(|ui| {
            let pane = format!("pane {}", self.pane + 1);
            egui::ComboBox::new("difference pane", "against").selected_text(pane).show_ui(ui, |ui| {
                for pane in 0..count {
                    ui.selectable_value(&mut self.pane, pane, format!("pane {}'s image", pane + 1));
                }
            });
            let against = |a: Against| match a {
                Against::Reference => "the reference".to_owned(),
                Against::Pane(other) => format!("pane {}'s image", other + 1),
            };
            egui::ComboBox::new("difference against", "as").selected_text(against(self.against)).show_ui(ui, |ui| {
                let others = (0..count).filter(|&p| p != self.pane).map(Against::Pane);
                for choice in [Against::Reference].into_iter().chain(others) {
                    ui.selectable_value(&mut self.against, choice, against(choice));
                }
            });
            ui.selectable_value(&mut self.metric, Metric::RelativeError, "relative error");
            ui.selectable_value(&mut self.metric, Metric::Signed, "signed");
        });
    }
}

/// a − b in luminance per pixel (Rec. 709), in a diverging colour map
/// symmetric about 0 (blue where a is darker, red where brighter), scaled
/// to the 99th percentile of |a − b|; None if the sizes differ.
pub fn signed_rgba(a: &LinearImage, b: &LinearImage) -> Option<(Vec<u8>, f64)> {
    if (a.width, a.height) != (b.width, b.height) {
        return None;
    }
    let luminance = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
    let signed: Vec<f64> = a.pixels.iter().zip(&b.pixels).map(|(&p, &q)| luminance(p) - luminance(q)).collect();
    let mut sizes: Vec<f64> = signed.iter().map(|d| d.abs()).filter(|d| d.is_finite()).collect();
    sizes.sort_by(f64::total_cmp);
    let top = sizes.get(sizes.len() * 99 / 100).copied().unwrap_or(1.0).max(1e-6);
    Some((signed.iter().flat_map(|&d| diverging(d / top)).collect(), top))
}

/// −1 blue, 0 white, +1 red (clamped); a NaN magenta, as `false_colour` flags it.
fn diverging(t: f64) -> [u8; 4] {
    if !t.is_finite() {
        return [255, 0, 255, 255];
    }
    let t = t.clamp(-1.0, 1.0);
    let fade = |c: f64| (255.0 * (1.0 - t.abs() * (1.0 - c))).round() as u8;
    match t >= 0.0 {
        true => [255, fade(0.1), fade(0.1), 255],
        false => [fade(0.1), fade(0.3), 255, 255],
    }
}

/// The colour scale under the image: its colours and its ends' values.
fn scale_ui(ui: &mut egui::Ui, metric: Metric, top: f64, width: f32) {
    let steps = 64;
    let colours: Vec<[u8; 4]> = match metric {
        Metric::RelativeError => {
            false_colour(&(0..steps).map(|i| i as f64 / (steps - 1) as f64).collect::<Vec<_>>(), 1.0)
        }
        Metric::Signed => (0..steps).map(|i| diverging(2.0 * i as f64 / (steps - 1) as f64 - 1.0)).collect(),
    };
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 12.0), egui::Sense::hover());
    let step = rect.width() / steps as f32;
    for (i, [r, g, b, _]) in colours.into_iter().enumerate() {
        let cell = egui::Rect::from_min_size(rect.min + egui::vec2(i as f32 * step, 0.0), egui::vec2(step + 0.5, 12.0));
        ui.painter().rect_filled(cell, 0.0, egui::Color32::from_rgb(r, g, b));
    }
    let ends = match metric {
        Metric::RelativeError => format!("0 … {top:.2e} (relative error, 99th percentile and above)"),
        Metric::Signed => format!("−{top:.2e} … 0 … +{top:.2e} (luminance, 99th percentile of |a − b|)"),
    };
    ui.label(ends);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brighter than the other image is red, darker blue, equal white, the
    /// scale the 99th percentile of the differences' size.
    #[test]
    fn the_signed_difference_is_red_above_blue_below() {
        let mut a = LinearImage::new(10, 10);
        let b = LinearImage { width: 10, height: 10, pixels: vec![[0.5; 3]; 100] };
        for (i, p) in a.pixels.iter_mut().enumerate() {
            *p = [0.5 + (i as f32 - 50.0) * 0.01; 3];
        }
        let (rgba, top) = signed_rgba(&a, &b).expect("same size");
        assert!((top - 0.5).abs() < 1e-5, "{top}");
        let pixel = |i: usize| [rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]];
        assert_eq!(pixel(50), [255, 255, 255]);
        let (above, below) = (pixel(90), pixel(10));
        assert!(above[0] == 255 && above[2] < 200, "{above:?}");
        assert!(below[2] == 255 && below[0] < 200, "{below:?}");
        assert_eq!(signed_rgba(&a, &LinearImage::new(5, 5)), None);
    }
}
