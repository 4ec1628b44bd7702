//! The Inspector: the selected object's name, material (kind, fields, preset) and transform, or
//! the selected point, spot or directional light.

use egui::{DragValue, Ui};

use super::material::{kind_list, kind_of, material_editor, with_kind};
use super::vec3_row;
use crate::app::RtApp;
use crate::presets::PRESETS;

/// Edits the selected point, spot or directional light.
fn light_inspector(app: &mut RtApp, ui: &mut Ui, index: usize) {
    let mut light = app.doc.scene.lights[index].clone();
    ui.horizontal(|ui| {
        ui.label("Name");
        ui.text_edit_singleline(&mut light.name)
            .on_hover_text("The light's name");
    });
    ui.horizontal_wrapped(|ui| {
        for kind in rt_core::LightKind::ALL {
            ui.selectable_value(&mut light.kind, kind, kind.label())
                .on_hover_text(kind.summary());
        }
    });
    let size = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-3));
    if light.kind != rt_core::LightKind::Directional {
        vec3_row(
            ui,
            "Position",
            &mut light.position,
            size * 0.005,
            "Where the light is",
        );
    }
    if light.kind != rt_core::LightKind::Point {
        vec3_row(
            ui,
            "Direction",
            &mut light.direction,
            0.01,
            "The way the light travels (need not be normalised)",
        );
    }
    ui.horizontal(|ui| {
        ui.label("Colour");
        ui.color_edit_button_rgb(&mut light.color)
            .on_hover_text("Colour of the light");
    });
    let unit = if light.kind == rt_core::LightKind::Directional {
        "W/m² (irradiance facing it)"
    } else {
        "W/sr (radiant intensity)"
    };
    ui.horizontal(|ui| {
        ui.label("Intensity");
        ui.add(
            DragValue::new(&mut light.intensity)
                .speed(0.1)
                .range(0.0..=1e12),
        )
        .on_hover_text(format!("Colour × intensity, in {unit}"));
        ui.weak(unit);
    });
    if light.kind == rt_core::LightKind::Spot {
        ui.add(egui::Slider::new(&mut light.inner_angle_deg, 0.0..=180.0).text("inner angle °"))
            .on_hover_text("Full intensity within this angle of the direction");
        ui.add(egui::Slider::new(&mut light.outer_angle_deg, 0.0..=180.0).text("outer angle °"))
            .on_hover_text("No light beyond this angle; a smooth falloff in between");
        light.outer_angle_deg = light.outer_angle_deg.max(light.inner_angle_deg);
    }
    if ui
        .button("Delete light")
        .on_hover_text("Remove this light (undo brings it back)")
        .clicked()
    {
        app.delete_delta_light(index);
        return;
    }
    if light != app.doc.scene.lights[index] {
        app.doc.edit(
            &format!("edit {}", light.name),
            &format!("light#{index}"),
            |s| s.lights[index] = light,
        );
    }
}

pub fn inspector_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Inspector");
    if let Some(index) = app
        .selected_light
        .filter(|&i| i < app.doc.scene.lights.len())
    {
        light_inspector(app, ui, index);
        return;
    }
    let Some(index) = app.selection.filter(|&i| i < app.doc.scene.objects.len()) else {
        ui.weak("Select an object in the list or click it in the viewport.");
        return;
    };
    let mut object = app.doc.scene.objects[index].clone();
    let texture_count = app.doc.scene.textures.len();
    let mut choose_texture = false;

    ui.horizontal(|ui| {
        ui.label("Name");
        ui.text_edit_singleline(&mut object.name)
            .on_hover_text("The object's name");
    });
    ui.horizontal(|ui| {
        ui.label(format!("{} triangles", object.mesh.indices.len()));
        let sharing = app
            .doc
            .scene
            .objects
            .iter()
            .filter(|o| std::sync::Arc::ptr_eq(&o.mesh, &object.mesh))
            .count();
        if sharing > 1 {
            ui.weak(format!("mesh shared by {sharing} objects"))
                .on_hover_text(
                    "Instances of one mesh (a glTF's shared meshes, or Duplicate as instance): \
                     stored once in projects and when rendering",
                );
        }
    });
    if object.mesh.normals.is_none()
        && ui
            .button("Shade smooth")
            .on_hover_text(
                "Give this flat-shaded mesh normals: smooth across edges under 30°, sharp \
                 above (as Blender's Auto Smooth); undo restores the facets",
            )
            .clicked()
    {
        object.mesh =
            std::sync::Arc::new(rt_core::smooth_normals::smooth_normals(&object.mesh, 30.0));
    }

    ui.add_space(4.0);
    ui.strong("Transform").on_hover_text(
        "Scale, then rotate (X, Y, Z in degrees), then translate; drag or type, arrow keys nudge",
    );
    let size = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-3));
    let t = &mut object.transform;
    vec3_row(
        ui,
        "Position",
        &mut t.translation,
        size * 0.005,
        "Where the object is",
    );
    vec3_row(
        ui,
        "Rotation °",
        &mut t.rotation_deg,
        0.5,
        "Rotation about X, Y, Z in degrees",
    );
    vec3_row(
        ui,
        "Scale",
        &mut t.scale,
        0.005,
        "Size along each axis (negative mirrors)",
    );

    ui.horizontal(|ui| {
        if ui
            .button("Frame")
            .on_hover_text("Point the camera at this object (F)")
            .clicked()
        {
            app.frame_selection();
        }
        if ui
            .button("Delete…")
            .on_hover_text("Delete this object (asks first; undo brings it back)")
            .clicked()
        {
            app.ui.pending_delete = Some(index);
        }
    });

    ui.add_space(4.0);
    ui.strong("Material");
    let current = kind_of(&object.material);
    ui.horizontal_wrapped(|ui| {
        ui.weak("Start from")
            .on_hover_text("Presets of the material below: each sets it to a simple kind");
        for (kind, label, tip) in kind_list() {
            if ui
                .selectable_label(current == kind, label)
                .on_hover_text(tip)
                .clicked()
                && current != kind
            {
                object.material = with_kind(&object.material, kind, texture_count);
            }
        }
    });
    material_editor(ui, &mut object.material, texture_count, &mut choose_texture);
    if let Some(material) = gallery(app, ui) {
        object.material = material;
    }
    shadow_catcher_toggle(
        ui,
        &mut object.shadow_catcher,
        app.doc.scene.settings.transparent,
    );

    if object != app.doc.scene.objects[index] {
        app.doc.edit(
            &format!("edit {}", object.name),
            &format!("object#{index}"),
            |s| s.objects[index] = object,
        );
    }
    if choose_texture
        && let Some(path) = rfd::FileDialog::new()
            .add_filter(
                "Images",
                &[
                    "png", "jpg", "jpeg", "tga", "bmp", "tif", "tiff", "webp", "gif", "dds", "qoi",
                    "ktx2", "ppm", "hdr", "exr",
                ],
            )
            .pick_file()
    {
        app.set_texture_from_file(index, &path);
    }
}

/// Cycles' Object ▸ Shadow Catcher; it needs a transparent film (Render panel) to show through.
fn shadow_catcher_toggle(ui: &mut Ui, catcher: &mut bool, transparent: bool) {
    ui.checkbox(catcher, "Shadow catcher").on_hover_text(
        "Show only the shadows and the reflections of other objects this receives, over a \
         transparent background: to composite renders over a photograph",
    );
    if *catcher && !transparent {
        ui.weak(
            "Needs \"Transparent background\" (Render panel): renders as its material until then.",
        );
    }
}

/// The presets as a gallery of thumbnails rendered by rt (`crate::gallery`; a name alone until
/// its thumbnail arrives): the material of the one clicked.
fn gallery(app: &mut RtApp, ui: &mut Ui) -> Option<rt_core::Material> {
    let mut chosen = None;
    // Closed at first: open, it pushes the Camera and Render panels down a screen.
    egui::CollapsingHeader::new("Gallery")
        .default_open(false)
        .show(ui, |ui| {
            app.gallery.start(ui.ctx().clone());
            app.gallery.poll(ui.ctx());
            let side = crate::gallery::THUMBNAIL_SIZE as f32;
            egui::Grid::new("gallery").num_columns(2).show(ui, |ui| {
                for (i, preset) in PRESETS.iter().enumerate() {
                    let button = match app.gallery.thumbnail(i) {
                        Some(t) => egui::Button::image_and_text(
                            egui::Image::new(t).fit_to_exact_size(egui::vec2(side, side)),
                            preset.name,
                        ),
                        None => egui::Button::new(preset.name)
                            .min_size(egui::vec2(side + 8.0, side + 8.0)),
                    };
                    if ui.add(button).on_hover_text(preset.tip).clicked() {
                        chosen = Some((preset.material)());
                    }
                    if i % 2 == 1 {
                        ui.end_row();
                    }
                }
            });
        })
        .header_response
        .on_hover_text("Replace the material with a named one (pictures rendered by rt)");
    chosen
}
