//! The Lights panel: the ambient colour, the environment map, the fog, the emissive objects and the
//! point, spot and directional lights, and the buttons that add lights.

use egui::{DragValue, Ui};

use super::is_light;
use crate::app::{LightShape, RtApp};

/// The environment map: which file, its rotation and strength (it replaces the ambient colour).
fn environment_rows(app: &mut RtApp, ui: &mut Ui) {
    let mut choose = false;
    let mut builtin = false;
    let mut sky = false;
    let mut remove = false;
    ui.horizontal(|ui| {
        ui.label("Environment").on_hover_text(
            "An HDR image around the scene that lights it (replaces the ambient colour)",
        );
        let name = app
            .doc
            .scene
            .environment
            .as_ref()
            .map_or("none".to_string(), |e| e.source.clone());
        ui.weak(name);
    });
    ui.horizontal(|ui| {
        choose = ui
            .button("Choose…")
            .on_hover_text("Load an equirectangular .hdr or .exr environment")
            .clicked();
        builtin = ui
            .button("Studio")
            .on_hover_text("The built-in studio environment (Poly Haven, CC0)")
            .clicked();
        sky = ui
            .button("Sun and sky")
            .on_hover_text(
                "A clear sky with the sun 35° up (Preetham's model); the rotation turns the sun \
                 around, the strength starts at 1/32 (daylight is bright)",
            )
            .clicked();
        remove = app.doc.scene.environment.is_some()
            && ui
                .button("None")
                .on_hover_text("Remove the environment (back to the ambient colour)")
                .clicked();
    });
    if let Some(env) = &app.doc.scene.environment {
        let (mut rotation, mut strength) = (env.rotation_deg, env.strength);
        let a = ui
            .add(egui::Slider::new(&mut rotation, -180.0..=180.0).text("rotation (°)"))
            .on_hover_text("Turns the environment about the up axis");
        let b = ui
            .add(
                egui::Slider::new(&mut strength, 0.0..=10.0)
                    .logarithmic(true)
                    .text("strength"),
            )
            .on_hover_text("Scales the environment's light");
        if a.changed() || b.changed() {
            app.doc.edit("change environment", "environment", |s| {
                if let Some(e) = s.environment.as_mut() {
                    e.rotation_deg = rotation;
                    e.strength = strength;
                }
            });
        }
    }
    if remove {
        app.doc
            .edit("remove environment", "remove environment", |s| {
                s.environment = None
            });
        app.doc.seal();
    }
    if builtin {
        match rt_io::assets::default_environment() {
            Ok(env) => {
                app.doc.edit("set environment", "set environment", |s| {
                    s.environment = Some(env)
                });
                app.doc.seal();
            }
            Err(e) => app.show_error(format!("The built-in environment did not load:\n{e}")),
        }
    }
    if sky {
        let env = rt_core::sky::SunSky {
            elevation_deg: 35.0,
            turbidity: 3.0,
        }
        .environment();
        app.doc.edit("set environment", "set environment", |s| {
            s.environment = Some(env)
        });
        app.doc.seal();
    }
    if choose
        && let Some(path) = rfd::FileDialog::new()
            .add_filter("HDR images", &["hdr", "exr", "png", "jpg", "jpeg"])
            .pick_file()
    {
        app.set_environment_from_file(&path);
    }
}

pub fn lights_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Lights");
    let mut ambient = app.doc.scene.ambient;
    ui.horizontal(|ui| {
        ui.label("Ambient").on_hover_text(
            "Radiance of rays that leave the scene (a uniform sky); colour × strength",
        );
        let strength = ambient.iter().copied().fold(0.0f32, f32::max);
        let mut color = if strength > 0.0 {
            ambient.map(|c| c / strength)
        } else {
            [1.0; 3]
        };
        let mut new_strength = strength;
        let a = ui
            .color_edit_button_rgb(&mut color)
            .on_hover_text("Ambient colour");
        let b = ui
            .add(
                DragValue::new(&mut new_strength)
                    .speed(0.01)
                    .range(0.0..=1e6),
            )
            .on_hover_text("Ambient strength (0 turns it off)");
        if a.changed() || b.changed() {
            ambient = color.map(|c| c * new_strength);
        }
    });
    if ambient != app.doc.scene.ambient {
        app.doc
            .edit("change ambient", "ambient", |s| s.ambient = ambient);
    }
    environment_rows(app, ui);
    super::fog::fog_rows(app, ui);
    let mut clicked = None;
    for (i, object) in app.doc.scene.objects.iter().enumerate() {
        if is_light(object) {
            let response = ui
                .selectable_label(app.selection == Some(i), object.name.as_str())
                .on_hover_text("An emissive object; select it to edit");
            if response.clicked() {
                clicked = Some(i);
            }
        }
    }
    if let Some(i) = clicked {
        app.select_object(Some(i));
    }
    let mut clicked_light = None;
    for (i, light) in app.doc.scene.lights.iter().enumerate() {
        if ui
            .selectable_label(app.selected_light == Some(i), &light.name)
            .on_hover_text(format!("A {:?} light; select it to edit", light.kind))
            .clicked()
        {
            clicked_light = Some(i);
        }
    }
    if let Some(i) = clicked_light {
        app.select_light(Some(i));
    }
    ui.horizontal(|ui| add_area_light_buttons(app, ui, "Add quad light"));
    ui.horizontal(|ui| {
        for kind in rt_core::LightKind::ALL {
            let placed = if kind.has_position() {
                "above the centre of the scene"
            } else {
                "at infinity"
            };
            if ui
                .button(format!("Add {}", kind.noun()))
                .on_hover_text(format!("{}, {placed}", kind.summary()))
                .clicked()
            {
                app.add_delta_light(kind);
            }
        }
    });
}

/// "Add box light" and the quad-light button, labelled `quad_label` (the Lights panel and the Edit
/// menu, which names the shortcut).
pub fn add_area_light_buttons(app: &mut RtApp, ui: &mut Ui, quad_label: &str) {
    if ui
        .button("Add box light")
        .on_hover_text("An emissive box at the centre of the scene")
        .clicked()
    {
        app.add_light(LightShape::Box);
    }
    if ui
        .button(quad_label)
        .on_hover_text("An emissive square facing down, at the centre of the scene")
        .clicked()
    {
        app.add_light(LightShape::Quad);
    }
}
