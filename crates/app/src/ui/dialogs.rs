//! Modal dialogs: errors, and the confirmation before deleting an object.

use crate::app::RtApp;

pub fn dialogs(app: &mut RtApp, ctx: &egui::Context) {
    if let Some(message) = app.ui.error.clone() {
        let response = egui::Modal::new(egui::Id::unique("error dialog")).show(ctx, |ui| {
            ui.set_max_width(480.0);
            ui.heading("Something went wrong");
            ui.label(&message);
            ui.add_space(8.0);
            ui.button("OK")
                .on_hover_text("Close this message; the scene is unchanged")
                .clicked()
        });
        if response.inner || response.should_close() {
            app.ui.error = None;
        }
    }
    if let Some(index) = app.ui.pending_delete {
        let Some(name) = app.doc.scene.objects.get(index).map(|o| o.name.clone()) else {
            app.ui.pending_delete = None;
            return;
        };
        let response = egui::Modal::new(egui::Id::unique("delete dialog")).show(ctx, |ui| {
            ui.heading(format!("Delete '{name}'?"));
            ui.label("Undo (Ctrl+Z) brings it back.");
            ui.add_space(8.0);
            ui.horizontal(|ui| {
                if ui
                    .button("Delete")
                    .on_hover_text("Delete the object")
                    .clicked()
                {
                    Some(true)
                } else if ui
                    .button("Cancel")
                    .on_hover_text("Keep the object")
                    .clicked()
                {
                    Some(false)
                } else {
                    None
                }
            })
            .inner
        });
        match response.inner {
            Some(true) => {
                app.delete_object(index);
                app.ui.pending_delete = None;
            }
            Some(false) => app.ui.pending_delete = None,
            None if response.should_close() => app.ui.pending_delete = None,
            None => {}
        }
    }
}
