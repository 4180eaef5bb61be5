//! The difference view: where pane 1 disagrees with the reference (at the
//! reference's size), or with pane 2, as relative error in false colour,
//! refreshed twice a second.

use std::time::Instant;

use eframe::egui;

use std::borrow::Cow;

use super::export::difference_rgba;
use super::panes::Panes;
use crate::analysis::reference::Reference;

#[derive(Default)]
pub struct Difference {
    texture: Option<egui::TextureHandle>,
    at: Option<Instant>,
}

impl Difference {
    pub fn difference_ui(&mut self, ctx: &egui::Context, panes: &Panes, reference: Option<&Reference>) {
        let refresh = self.at.is_none_or(|t| t.elapsed().as_secs_f32() > 0.5);
        let mut caption = "Needs a reference, or two panes of the same size".to_owned();
        let first = panes.list().first().map(|p| &p.state().image);
        let against_reference = first.zip(reference).and_then(|(image, r)| {
            Some((image.at_size(r.image.width, r.image.height)?, &r.image, "pane 1 against the reference"))
        });
        let against_pane = || match panes.list() {
            [first, second, ..] => {
                Some((Cow::Borrowed(&first.state().image), &second.state().image, "pane 1 against pane 2"))
            }
            _ => None,
        };
        if let Some((a, against, label)) = against_reference.or_else(against_pane) {
            caption = format!("relative error, {label}");
            if refresh {
                if let Some((rgba, top)) = difference_rgba(&a, against) {
                    let image = egui::ColorImage::from_rgba_unmultiplied([a.width as usize, a.height as usize], &rgba);
                    self.texture = Some(ctx.load_texture("difference", image, egui::TextureOptions::NEAREST));
                    self.at = Some(Instant::now());
                    caption = format!("relative error, {label}; white = {top:.2e}");
                }
            }
        }
        egui::Window::new("Difference").default_size([360.0, 300.0]).show(ctx, |ui| {
            ui.label(&caption);
            if let Some(texture) = &self.texture {
                let size = texture.size_vec2();
                let scale = (ui.available_width() / size.x).min(2.0);
                ui.image((texture.id(), size * scale));
            }
        });
        ctx.request_repaint_after(std::time::Duration::from_millis(500));
    }
}
