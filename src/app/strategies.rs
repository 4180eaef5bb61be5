//! The strategy view: for a bidirectional pane, what each way of making a
//! path brings to its image — paths of k segments (rows) made with s
//! vertices from the light (s = 0: the camera path met the light; s = 1:
//! next-event estimation; s = k: a light path joined to the camera) or
//! merged at a camera vertex — weighted by multiple importance sampling, or
//! not (each strategy alone, its own estimate of all such light), refining
//! with the pane. Hovering a strategy shows its share of the pane's light.

use std::sync::Arc;

use eframe::egui;

use crate::render::image::Tonemap;
use crate::render::integrators::bidir::strategies::{StrategyImages, MAX_LENGTH};

/// A pane's strategy window: open or not, which images, their textures.
#[derive(Default)]
pub struct StrategyView {
    pub open: bool,
    pub weighted: bool,
    shown: Option<Arc<StrategyImages>>,
    textures: Vec<egui::TextureHandle>,
}

impl StrategyView {
    /// Bring the textures up to `images` (only when new ones came).
    fn update(&mut self, ctx: &egui::Context, images: &Arc<StrategyImages>, exposure: f32) {
        let fresh = self.shown.as_ref().is_none_or(|shown| !Arc::ptr_eq(shown, images));
        if !fresh && self.textures.len() == images.strategies.len() {
            return;
        }
        let tonemap = Tonemap::new(exposure);
        let size = [images.width as usize, images.height as usize];
        let layers = if self.weighted { &images.weighted } else { &images.unweighted };
        self.textures = layers
            .iter()
            .enumerate()
            .map(|(i, pixels)| {
                let colors = pixels.iter().map(|p| {
                    let [r, g, b] = tonemap.pixel(*p);
                    egui::Color32::from_rgb(r, g, b)
                });
                let image = egui::ColorImage::new(size, colors.collect());
                ctx.load_texture(format!("strategy {i}"), image, egui::TextureOptions::NEAREST)
            })
            .collect();
        self.shown = Some(images.clone());
    }
}

/// The window of pane `index`'s strategies, while it is open: `images`
/// the latest, shown at `exposure`, their shares of `pane_light` (the
/// pane's mean).
pub fn strategies_ui(
    ctx: &egui::Context,
    index: usize,
    view: &mut StrategyView,
    images: Option<Arc<StrategyImages>>,
    exposure: f32,
    pane_light: f64,
) {
    let mut open = view.open;
    egui::Window::new(format!("Strategies of pane {}", index + 1))
        .open(&mut open)
        .resizable(true)
        // Room for the longest row (six strategies of 140 points) and all five rows.
        .default_size([920.0, 640.0])
        // At the bottom right, over the plots: not over the pane's buttons,
        // its own "Strategies" among them.
        .pivot(egui::Align2::RIGHT_BOTTOM)
        .default_pos(ctx.content_rect().right_bottom() - egui::vec2(16.0, 16.0))
        .show(ctx, |ui| {
            let before = view.weighted;
            ui.horizontal(|ui| {
                ui.radio_value(&mut view.weighted, true, "weighted (what the image holds)");
                ui.radio_value(&mut view.weighted, false, "unweighted (each strategy alone)");
            });
            if view.weighted != before {
                view.shown = None;
            }
            let Some(images) = images else {
                ui.weak("Waiting for the first pass…");
                return;
            };
            view.update(ctx, &images, exposure);
            ui.small(format!(
                "{} passes; paths of up to {MAX_LENGTH} segments; s: vertices from the light, t: from the camera; \
             strategies that brought no light yet are left out",
                images.passes
            ));
            let thumb = egui::vec2(images.width as f32, images.height as f32) * (140.0 / images.width.max(1) as f32);
            egui::ScrollArea::both().show(ui, |ui| {
                for length in 1..=MAX_LENGTH {
                    ui.horizontal(|ui| {
                        ui.label(format!("k = {length}"));
                        for (i, strategy) in images
                            .strategies
                            .iter()
                            .enumerate()
                            .filter(|&(i, s)| s.length() == length && images.brought_light[i])
                        {
                            let response = ui
                                .vertical(|ui| {
                                    let response = ui.image((view.textures[i].id(), thumb));
                                    ui.small(strategy.label());
                                    response
                                })
                                .inner;
                            let light =
                                images.weighted[i].iter().map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).sum::<f64>()
                                    / images.weighted[i].len().max(1) as f64;
                            let share = if pane_light > 0.0 { 100.0 * light / pane_light } else { 0.0 };
                            let text = format!("{}: {share:.1}% of the pane's light", strategy.label());
                            response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, &text));
                            response.on_hover_text(text);
                        }
                    });
                }
            });
        });
    view.open = open;
}
