//! The fog rows of the Lights panel (`rt_core::fog`): how dense, what colour it scatters, and how
//! much forward.

use egui::{DragValue, Ui};

use crate::app::RtApp;

pub fn fog_rows(app: &mut RtApp, ui: &mut Ui) {
    let mut fog = app.doc.scene.fog;
    // The scene's size sets the scale a density means: 1/size is one mean free path across it.
    let size = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-6));
    let mut added = false;
    ui.horizontal(|ui| {
        ui.label("Fog").on_hover_text(
            "A haze filling the space outside closed objects: it dims what lies behind it and \
             glows where light crosses it (beams, halos)",
        );
        ui.add(
            DragValue::new(&mut fog.density)
                .speed(0.01 / size)
                .range(0.0..=1e6)
                .max_decimals(6),
        )
        .on_hover_text("Density: how much fog per unit of distance (0: none)");
        if !fog.is_on()
            && ui
                .button("Add fog")
                .on_hover_text("Fog that light crosses the scene through about once")
                .clicked()
        {
            fog.density = 1.0 / size;
            added = true;
        }
    });
    if fog.is_on() {
        ui.horizontal(|ui| {
            ui.color_edit_button_rgb(&mut fog.albedo)
                .on_hover_text("The share of light the fog scatters, per colour (black: smoke)");
            ui.add(egui::Slider::new(&mut fog.anisotropy, -0.95..=0.95).text("forward"))
                .on_hover_text(
                    "How much the fog scatters light onward (haze round lamps) rather than back",
                );
        });
        ui.weak(format!(
            "light travels {:.3} units on average before it meets the fog",
            1.0 / fog.density
        ));
        let scene = &app.doc.scene;
        let infinite = scene.environment.is_some()
            || scene
                .lights
                .iter()
                .any(|l| l.kind == rt_core::LightKind::Directional);
        if infinite {
            ui.weak("The sun and the environment do not reach through fog");
        }
    }
    if fog != app.doc.scene.fog {
        app.doc.edit("change fog", "fog", |s| s.fog = fog);
        // A click is a step of its own; drags merge until released.
        if added {
            app.doc.seal();
        }
    }
}
