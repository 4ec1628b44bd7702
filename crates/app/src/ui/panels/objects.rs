//! The Objects panel: the scene's objects (lights aside), one selectable row each.

use egui::Ui;

use super::is_light;
use crate::app::RtApp;

pub fn objects_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Objects");
    let mut clicked = None;
    for (i, object) in app.doc.scene.objects.iter().enumerate() {
        if is_light(object) {
            continue;
        }
        let response = ui
            .selectable_label(app.selection == Some(i), &object.name)
            .on_hover_text(format!(
                "{} triangles, {}",
                object.mesh.indices.len(),
                object.material.kind_name()
            ));
        if response.clicked() {
            clicked = Some(i);
        }
    }
    if app.doc.scene.objects.iter().all(is_light) {
        ui.weak("No objects: open an OBJ (File > Open).");
    }
    if let Some(i) = clicked {
        app.select_object(Some(i));
    }
}
