//! The studio's editing widgets. A number typed into a field is one edit,
//! taken when it is committed (Enter, or the field losing focus), not at
//! each keystroke: typing `0.45` would otherwise render radius 0 and 0.4 on
//! the way, each an undo step of its own. Escape leaves the value as it was.

use eframe::egui;
use egui::emath::Numeric;

/// A drag value that takes typed text when it is committed.
pub fn number<N: Numeric>(value: &mut N) -> egui::DragValue<'_> {
    egui::DragValue::new(value).update_while_editing(false)
}

/// A slider whose value field takes typed text when it is committed.
pub fn slider<N: Numeric>(value: &mut N, range: std::ops::RangeInclusive<N>) -> egui::Slider<'_> {
    egui::Slider::new(value, range).update_while_editing(false)
}

/// A one-line text field for `text` that changes it only when the typing is
/// committed; `key` tells apart the things edited in the same place (a name
/// being typed stays with its own item when another is selected). Returns
/// whether `text` changed.
pub fn committed_text_ui(
    ui: &mut egui::Ui,
    text: &mut String,
    key: impl std::hash::Hash + std::fmt::Debug,
) -> egui::InnerResponse<bool> {
    let id = ui.scope_id().with(("committed text", key));
    let mut typed = ui.data_mut(|d| d.get_temp::<String>(id)).unwrap_or_else(|| text.clone());
    let response = ui.add(egui::TextEdit::singleline(&mut typed).id(id));
    let commit = response.lost_focus() && !ui.input(|i| i.key_pressed(egui::Key::Escape));
    let changed = commit && typed != *text;
    if response.has_focus() {
        ui.data_mut(|d| d.insert_temp(id, typed));
    } else {
        ui.data_mut(|d| d.remove::<String>(id));
        if changed {
            *text = typed;
        }
    }
    egui::InnerResponse::new(changed, response)
}
