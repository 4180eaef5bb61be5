//! The panes: one, two or four, each with its own algorithm and settings,
//! all rendering the document's scene. Laid out in a grid, restarted
//! together when the scene changes, and measured against the scene's
//! reference.

use std::path::PathBuf;
use std::sync::Arc;

use eframe::egui;

use super::document::Document;
use super::inspector::Selection;
use super::pane::Pane;
use super::viewport::viewport_ui;
use crate::render::{Algorithm, LinearImage, RenderSettings};
use crate::scene::{presets, Scene, SceneSettings, ValidScene};

pub struct Panes {
    list: Vec<Pane>,
    /// Where each pane's image was drawn last frame, and the panes' whole
    /// area (screen points).
    rects: Vec<egui::Rect>,
    area: egui::Rect,
    reference: Option<LinearImage>,
    ctx: egui::Context,
}

fn default_algorithms(count: usize) -> Vec<Algorithm> {
    match count {
        1 => vec![Algorithm::Path],
        2 => vec![Algorithm::Path, Algorithm::Whitted],
        _ => Algorithm::ALL.to_vec(),
    }
}

/// 1, 2 or 4: three panes are shown as four.
pub fn pane_count(wanted: usize) -> usize {
    match wanted.clamp(1, 4) {
        3 => 4,
        n => n,
    }
}

impl Panes {
    pub fn new(ctx: &egui::Context) -> Self {
        Self { list: Vec::new(), rects: Vec::new(), area: egui::Rect::NOTHING, reference: None, ctx: ctx.clone() }
    }

    /// A pane's settings for `algorithm` among `count` panes of a scene.
    pub fn default_settings(algorithm: Algorithm, count: usize, scene: &SceneSettings) -> RenderSettings {
        // Four panes share the cores: each renders at half size
        let divisor = if count >= 4 { 2 } else { 1 };
        RenderSettings {
            width: (scene.width / divisor).max(16),
            height: (scene.height / divisor).max(16),
            samples_per_pixel: Some(4096),
            preview: true,
            ..RenderSettings::for_algorithm(algorithm)
        }
    }

    /// `count` panes, pane i with `saved[i]` (its defaults where None or
    /// missing) and `exposures[i]` (the scene's where missing).
    pub fn build(&mut self, count: usize, saved: &[Option<RenderSettings>], exposures: &[f32], scene: &SceneSettings) {
        let algorithms = default_algorithms(count);
        self.list = (0..count)
            .map(|i| {
                let settings = saved
                    .get(i)
                    .cloned()
                    .flatten()
                    .unwrap_or_else(|| Self::default_settings(algorithms[i], count, scene));
                Pane::new(&self.ctx, settings, exposures.get(i).copied().unwrap_or(scene.exposure))
            })
            .collect();
        self.rects.clear();
    }

    /// The same panes for a new scene: its size and exposure for every one.
    pub fn rebuild_for(&mut self, scene: &SceneSettings) {
        let count = self.list.len();
        let saved: Vec<Option<RenderSettings>> = (self.list.iter())
            .map(|p| {
                let sized = Self::default_settings(p.algorithm(), count, scene);
                Some(RenderSettings { width: sized.width, height: sized.height, ..p.settings().clone() })
            })
            .collect();
        self.build(count, &saved, &vec![scene.exposure; count], scene);
    }

    pub fn count(&self) -> usize {
        self.list.len()
    }

    pub fn list(&self) -> &[Pane] {
        &self.list
    }

    pub fn list_mut(&mut self) -> &mut [Pane] {
        &mut self.list
    }

    /// Where each pane's image was drawn last frame.
    pub fn rects(&self) -> &[egui::Rect] {
        &self.rects
    }

    /// The panes' whole area (the comparison sheet).
    pub fn area(&self) -> egui::Rect {
        self.area
    }

    pub fn restart_all(&mut self, scene: &Arc<ValidScene>) {
        for pane in &mut self.list {
            pane.restart(scene.clone());
        }
    }

    pub fn pause_all(&mut self) {
        self.list.iter_mut().for_each(Pane::pause);
    }

    pub fn reference(&self) -> Option<&LinearImage> {
        self.reference.as_ref()
    }

    /// The stored reference of the preset `scene` is, if it is one: the
    /// panes' error is measured against it where their size matches.
    pub fn load_reference_for(&mut self, scene: &Scene) {
        let name = presets::names().find(|n| presets::preset(n).and_then(Result::ok).is_some_and(|s| *s == *scene));
        let path = |name: &str| PathBuf::from(format!("assets/references/{name}.exr"));
        self.reference = name.and_then(|name| LinearImage::load(&path(name)).ok());
    }

    /// Take every pane's waiting events, measuring against the reference
    /// where the pane's size matches it.
    pub fn poll(&mut self) {
        let reference = &self.reference;
        for pane in &mut self.list {
            let settings = pane.settings();
            let matching = reference.as_ref().filter(|r| r.width == settings.width && r.height == settings.height);
            pane.poll(matching);
        }
    }

    /// Whether every pane has `passes` passes, or is done, or failed.
    pub fn all_have(&self, passes: u32) -> bool {
        self.list.iter().all(|p| p.state().passes() >= passes || p.state().finished || p.state().failed.is_some())
    }

    /// The grid of panes, each with its header (algorithm, settings,
    /// restart) and viewport.
    pub fn panes_ui(&mut self, ui: &mut egui::Ui, document: &mut Document, selection: &mut Selection) {
        self.area = ui.max_rect();
        let count = self.list.len();
        let columns = if count == 1 { 1 } else { 2 };
        let rows = count.div_ceil(columns);
        let cell = egui::vec2(ui.available_width() / columns as f32, ui.available_height() / rows as f32);
        let origin = ui.min_rect().min;
        self.rects.resize(count, egui::Rect::NOTHING);
        for index in 0..count {
            let (row, column) = (index / columns, index % columns);
            let min = origin + egui::vec2(column as f32 * cell.x, row as f32 * cell.y);
            let rect = egui::Rect::from_min_size(min, cell).shrink(3.0);
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect).id_salt(("pane", index)));
            self.rects[index] = self.pane_ui(&mut child, index, document, selection);
        }
    }

    fn pane_ui(
        &mut self,
        ui: &mut egui::Ui,
        index: usize,
        document: &mut Document,
        selection: &mut Selection,
    ) -> egui::Rect {
        let pane = &mut self.list[index];
        let mut restart = false;
        ui.horizontal(|ui| {
            restart |= pane.algorithm_ui(ui, index);
            ui.menu_button("Settings", |ui| restart |= pane.settings_ui(ui));
            restart |= ui.small_button("Restart").on_hover_text("Restart this pane").clicked();
        });
        if restart {
            if let Some(scene) = document.valid() {
                pane.restart(scene.clone());
            }
        }
        viewport_ui(ui, pane, document, selection).rect
    }

    /// The generation each pane is rendering (tests watch restarts with it).
    pub fn generations(&self) -> Vec<u64> {
        self.list.iter().map(|p| p.state().generation).collect()
    }
}
