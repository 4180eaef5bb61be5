//! The panes: one, two or four, each with its own algorithm and settings,
//! all rendering the document's scene. Laid out in a grid, restarted
//! together when the scene changes, and measured against the scene's
//! reference.

use std::sync::Arc;

use eframe::egui;

use super::document::Document;
use super::image_view::ImageView;
use super::inspector::Selection;
use super::outline::Outline;
use super::pane::Pane;
use super::viewport::{viewport_ui, Look};
use super::wipe::{Against, ReferenceTextures, Wipe};
use crate::analysis::reference::Reference;
use crate::render::{Algorithm, RenderSettings, Workers};
use crate::scene::{SceneSettings, ValidScene};

pub struct Panes {
    list: Vec<Pane>,
    /// Where each pane's image was drawn last frame, and the panes' whole
    /// area (screen points).
    rects: Vec<egui::Rect>,
    area: egui::Rect,
    /// The render threads every pane shares (None: the OS refused them).
    workers: Option<Workers>,
    ctx: egui::Context,
    /// How every pane shows its image: zoom, pan, the point read out.
    view: ImageView,
    /// Each pane's wipe to another pane's image or the reference, if on.
    wipes: Vec<Option<Wipe>>,
    reference_textures: ReferenceTextures,
    /// Each pane's outline of the selected object.
    outlines: Vec<Outline>,
}

/// The four panes' algorithms at first: the thesis' three and progressive
/// photon mapping (the bidirectional ones are a click away).
pub const FOUR: [Algorithm; 4] = [Algorithm::Whitted, Algorithm::Path, Algorithm::Photon, Algorithm::Sppm];

fn default_algorithms(count: usize) -> Vec<Algorithm> {
    match count {
        1 => vec![Algorithm::Path],
        2 => vec![Algorithm::Path, Algorithm::Whitted],
        _ => FOUR.to_vec(),
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
    /// Panes that share `workers`.
    pub fn new(ctx: &egui::Context, workers: Option<Workers>) -> Self {
        Self {
            list: Vec::new(),
            rects: Vec::new(),
            area: egui::Rect::NOTHING,
            workers,
            ctx: ctx.clone(),
            view: ImageView::default(),
            wipes: Vec::new(),
            reference_textures: ReferenceTextures::default(),
            outlines: Vec::new(),
        }
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
    /// A pane without saved settings gets the first of the layout's default
    /// algorithms that no saved pane has.
    pub fn build(&mut self, count: usize, saved: &[Option<RenderSettings>], exposures: &[f32], scene: &SceneSettings) {
        let taken: Vec<Algorithm> = saved.iter().take(count).flatten().map(RenderSettings::algorithm).collect();
        let mut spare = default_algorithms(count).into_iter().filter(|a| !taken.contains(a));
        self.list = (0..count)
            .map(|i| {
                let settings = match saved.get(i).cloned().flatten() {
                    Some(settings) => settings,
                    None => Self::default_settings(spare.next().unwrap_or(Algorithm::Path), count, scene),
                };
                let exposure = exposures.get(i).copied().unwrap_or(scene.exposure);
                Pane::new(&self.ctx, self.workers.as_ref(), settings, exposure)
            })
            .collect();
        self.rects.clear();
    }

    /// The same panes for a new scene: its size and exposure for every one.
    pub fn rebuild_for(&mut self, scene: &SceneSettings) {
        let count = self.list.len();
        let kept = self.kept_settings(count, scene);
        self.build(count, &kept, &vec![scene.exposure; count], scene);
    }

    /// `count` panes in place of these: the first keep their algorithms,
    /// settings and exposures (at the new layout's size), new ones come
    /// with their defaults.
    pub fn set_count(&mut self, count: usize, scene: &SceneSettings) {
        let kept = self.kept_settings(count, scene);
        let exposures: Vec<f32> = self.list.iter().take(count).map(Pane::exposure).collect();
        self.build(count, &kept, &exposures, scene);
    }

    /// The first `count` panes' settings, sized for `count` panes of `scene`.
    fn kept_settings(&self, count: usize, scene: &SceneSettings) -> Vec<Option<RenderSettings>> {
        (self.list.iter().take(count))
            .map(|p| {
                let sized = Self::default_settings(p.algorithm(), count, scene);
                Some(RenderSettings { width: sized.width, height: sized.height, ..p.settings().clone() })
            })
            .collect()
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

    /// Take every pane's waiting events, measuring against `reference`
    /// where a pane's size divides into it.
    pub fn poll(&mut self, reference: Option<&Reference>) {
        for pane in &mut self.list {
            pane.poll(reference);
        }
    }

    /// Whether every pane has `passes` passes, or is done, or failed.
    pub fn all_have(&self, passes: u32) -> bool {
        self.list.iter().all(|p| p.state().passes() >= passes || p.state().finished || p.state().failed.is_some())
    }

    /// The grid of panes, each with its header (algorithm, settings,
    /// restart, use as reference) and viewport. Returns the pane whose
    /// image the user made the reference.
    pub fn panes_ui(
        &mut self,
        ui: &mut egui::Ui,
        document: &mut Document,
        selection: &mut Selection,
        reference: Option<&Reference>,
    ) -> Option<usize> {
        self.area = ui.max_rect();
        // F: every image whole again (not while a field is being typed in)
        if ui.ctx().memory(|m| m.focused().is_none()) && ui.input(|i| i.key_pressed(egui::Key::F)) {
            self.view.fit();
        }
        // The point read out is last frame's: this frame's is known once
        // every pane has been asked where the pointer is
        let shown = self.view.hovered.take();
        let count = self.list.len();
        let columns = if count == 1 { 1 } else { 2 };
        let rows = count.div_ceil(columns);
        let cell = egui::vec2(ui.available_width() / columns as f32, ui.available_height() / rows as f32);
        let origin = ui.min_rect().min;
        self.rects.resize(count, egui::Rect::NOTHING);
        self.wipes.resize(count, None);
        self.outlines.resize_with(count, Outline::default);
        for (index, wipe) in self.wipes.iter_mut().enumerate() {
            // A wipe to a pane that went away ends
            if wipe.is_some_and(|w| matches!(w.other, Against::Pane(other) if other >= count || other == index)) {
                *wipe = None;
            }
        }
        let mut promoted = None;
        for index in 0..count {
            let (row, column) = (index / columns, index % columns);
            let min = origin + egui::vec2(column as f32 * cell.x, row as f32 * cell.y);
            let rect = egui::Rect::from_min_size(min, cell).shrink(3.0);
            let mut child = ui.new_child(egui::UiBuilder::new().max_rect(rect).id_salt(("pane", index)));
            let (drawn, promote) = self.pane_ui(&mut child, index, document, selection, shown, reference);
            self.rects[index] = drawn;
            if promote {
                promoted = Some(index);
            }
        }
        promoted
    }

    #[allow(clippy::too_many_arguments)]
    fn pane_ui(
        &mut self,
        ui: &mut egui::Ui,
        index: usize,
        document: &mut Document,
        selection: &mut Selection,
        shown: Option<egui::Vec2>,
        reference: Option<&Reference>,
    ) -> (egui::Rect, bool) {
        let count = self.list.len();
        let other_texture = match self.wipes[index].map(|w| w.other) {
            Some(Against::Pane(other)) => self.list[other].texture_id(),
            Some(Against::Reference) => {
                let exposure = self.list[index].exposure();
                reference.map(|r| self.reference_textures.texture(&self.ctx, index, r, exposure))
            }
            None => None,
        };
        let pane = &mut self.list[index];
        let wipe = &mut self.wipes[index];
        let (mut restart, mut promote) = (false, false);
        // Wrapped within the pane's own width: a row that ran on would put
        // its last buttons in the next pane's header
        ui.horizontal_wrapped(|ui| {
            restart |= pane.algorithm_ui(ui, index);
            ui.menu_button("Settings", |ui| restart |= pane.settings_ui(ui));
            restart |= ui.small_button("Restart").on_hover_text("Restart this pane").clicked();
            let hint = "Measure every pane against this pane's image from now on";
            promote |= ui.small_button("Use as reference").on_hover_text(hint).clicked();
            let hint = "Show another pane's image, or the reference, right of a divider you drag";
            ui.menu_button("Wipe", |ui| wipe_menu_ui(ui, wipe, index, count)).response.on_hover_text(hint);
            if pane.has_strategies() {
                let open = pane.strategy_view_mut().open;
                let hint = "What each way of joining light and camera paths brings to this pane, from the next pass";
                if ui.selectable_label(open, "Strategies").on_hover_text(hint).clicked() {
                    pane.show_strategies(!open);
                }
            }
        });
        if pane.strategy_view_mut().open && pane.has_strategies() {
            pane.strategies_ui(ui.ctx(), index);
        }
        if restart {
            if let Some(scene) = document.valid() {
                pane.restart(scene.clone());
            }
        }
        let reference = reference.map(|r| &r.image);
        let wipe = match (wipe.as_mut(), other_texture) {
            (Some(wipe), Some(texture)) => {
                let other = match wipe.other {
                    Against::Pane(other) => format!("pane {}", other + 1),
                    Against::Reference => "reference".to_string(),
                };
                let names = [format!("pane {}", index + 1), other];
                Some((wipe, texture, names))
            }
            _ => None,
        };
        let object = match *selection {
            Selection::Object(object) => Some(object),
            _ => None,
        };
        let (width, height) = (pane.state().image.width, pane.state().image.height);
        // Panes of one size share one outline: worked out once, not once a pane
        if !self.outlines[index].is_for(document, object, width, height) {
            match (0..index).find(|&i| self.outlines[i].is_for(document, object, width, height)) {
                Some(same) => self.outlines[index] = self.outlines[same].clone(),
                None => self.outlines[index].update(document, object, width, height),
            }
        }
        let outline = &self.outlines[index];
        let look = Look { view: &mut self.view, shown, reference, wipe, outline };
        (viewport_ui(ui, pane, document, selection, look).rect, promote)
    }

    /// Pane `index`'s wipe, if on.
    pub fn wipe(&self, index: usize) -> Option<Wipe> {
        self.wipes.get(index).copied().flatten()
    }

    /// Pane `index`'s outline of the selected object: its edges, in image fractions.
    pub fn outline(&self, index: usize) -> &[[egui::Vec2; 2]] {
        self.outlines.get(index).map_or(&[], |o| o.edges())
    }

    /// How the panes show their images.
    pub fn view(&self) -> &ImageView {
        &self.view
    }

    /// The generation each pane is rendering (tests watch restarts with it).
    pub fn generations(&self) -> Vec<u64> {
        self.list.iter().map(|p| p.state().generation).collect()
    }
}

/// The choice of the pane wiped over pane `index`, or none.
fn wipe_menu_ui(ui: &mut egui::Ui, wipe: &mut Option<Wipe>, index: usize, count: usize) {
    if ui.selectable_label(wipe.is_none(), "Off").clicked() {
        *wipe = None;
        ui.close();
    }
    let others = (0..count)
        .filter(|&other| other != index)
        .map(|other| (Against::Pane(other), format!("with pane {}", other + 1)));
    for (other, label) in others.chain([(Against::Reference, "with the reference".to_string())]) {
        let on = wipe.is_some_and(|w| w.other == other);
        if ui.selectable_label(on, label).clicked() {
            *wipe = Some(Wipe::new(other));
            ui.close();
        }
    }
}
