//! The status bar: the GPU in use, the scene's size, the last render time and the latest message.

use egui::Ui;

use crate::app::RtApp;

pub fn status_bar(app: &mut RtApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        let renders_on = if app.ui.render_device.on_cpu(false).0 {
            rt_gpu::progressive::cpu_label()
        } else {
            app.adapter_label()
        };
        ui.label(format!("renders on {renders_on}"))
            .on_hover_text("What renders the render windows (the Render panel's Device)");
        ui.separator();
        ui.label(format!(
            "{} objects, {} triangles",
            app.doc.scene.objects.len(),
            app.doc.scene.triangle_count()
        ));
        ui.separator();
        match app.ui.last_render {
            Some(d) => ui.label(format!("last render {:.2} s", d.as_secs_f32())),
            None => ui.label("no render yet"),
        };
        if !app.ui.status.is_empty() {
            ui.separator();
            ui.label(&app.ui.status);
        }
    });
}
