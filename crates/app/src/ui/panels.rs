//! Side panels: the object and light lists, the inspector (material, transform), the camera and the
//! render settings, and the status bar. Each edits a copy and commits it as one undoable edit.

use egui::{DragValue, Ui};
use rt_core::{Material, Object};

use crate::app::{LightShape, RtApp};
use crate::presets::PRESETS;

fn is_light(o: &Object) -> bool {
    matches!(o.material, Material::Emissive { .. })
}

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
        match rt_core::assets::default_environment() {
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
        if ui
            .button("Add point light")
            .on_hover_text("A point light above the centre of the scene (intensity in W/sr)")
            .clicked()
        {
            app.add_delta_light(rt_core::LightKind::Point);
        }
        if ui
            .button("Add spot light")
            .on_hover_text("A spot light above the centre of the scene, pointing down")
            .clicked()
        {
            app.add_delta_light(rt_core::LightKind::Spot);
        }
        if ui
            .button("Add sun")
            .on_hover_text("A directional light: parallel light from far away (irradiance in W/m²)")
            .clicked()
        {
            app.add_delta_light(rt_core::LightKind::Directional);
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

/// Edits the selected point, spot or directional light.
fn light_inspector(app: &mut RtApp, ui: &mut Ui, index: usize) {
    let mut light = app.doc.scene.lights[index].clone();
    ui.horizontal(|ui| {
        ui.label("Name");
        ui.text_edit_singleline(&mut light.name)
            .on_hover_text("The light's name");
    });
    ui.horizontal_wrapped(|ui| {
        for (kind, label, tip) in [
            (
                rt_core::LightKind::Point,
                "Point",
                "Light from a point, in every direction",
            ),
            (
                rt_core::LightKind::Spot,
                "Spot",
                "Light from a point, in a cone",
            ),
            (
                rt_core::LightKind::Directional,
                "Sun",
                "Parallel light from far away",
            ),
        ] {
            ui.selectable_value(&mut light.kind, kind, label)
                .on_hover_text(tip);
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

/// The material kinds offered in the inspector.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Diffuse,
    Textured,
    Metal,
    Glass,
    Emissive,
    Pbr,
}

fn kind_of(m: &Material) -> Kind {
    match m {
        Material::Lambertian { texture: None, .. } => Kind::Diffuse,
        Material::Lambertian { .. } => Kind::Textured,
        Material::Metal { .. } => Kind::Metal,
        Material::Dielectric { .. } => Kind::Glass,
        Material::Emissive { .. } => Kind::Emissive,
        Material::Pbr(_) => Kind::Pbr,
    }
}

/// The main colour of a material, carried over when its kind changes.
fn color_of(m: &Material) -> [f32; 3] {
    match m {
        Material::Lambertian { albedo, .. } | Material::Metal { albedo, .. } => *albedo,
        Material::Dielectric { tint, .. } => *tint,
        Material::Emissive { color, .. } => *color,
        Material::Pbr(p) => p.base_color,
    }
}

fn with_kind(m: &Material, kind: Kind, textures: usize) -> Material {
    let color = color_of(m);
    match kind {
        Kind::Diffuse => Material::lambertian(color),
        // A texture slot without an image renders white until an image is chosen.
        Kind::Textured => Material::Lambertian {
            albedo: [1.0; 3],
            texture: (textures > 0).then_some(0),
        },
        Kind::Metal => Material::Metal {
            albedo: color,
            fuzz: 0.1,
        },
        Kind::Glass => Material::Dielectric {
            ior: 1.5,
            tint: [1.0; 3],
        },
        Kind::Emissive => Material::Emissive {
            color,
            intensity: 10.0,
        },
        Kind::Pbr => Material::Pbr(Box::new(rt_core::material::Pbr {
            base_color: color,
            ..Default::default()
        })),
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
    ui.label(format!("{} triangles", object.mesh.indices.len()));

    ui.add_space(4.0);
    ui.strong("Material");
    let current = kind_of(&object.material);
    ui.horizontal_wrapped(|ui| {
        for (kind, label, tip) in [
            (Kind::Diffuse, "Diffuse", "Lambertian: matte, one colour"),
            (
                Kind::Textured,
                "Texture",
                "Lambertian with an image as its colour",
            ),
            (Kind::Metal, "Metal", "A mirror, blurred by fuzz"),
            (Kind::Glass, "Glass", "A smooth dielectric that refracts"),
            (
                Kind::Emissive,
                "Emissive",
                "A light source (emits from its front faces)",
            ),
            (
                Kind::Pbr,
                "Physically based",
                "glTF metallic-roughness: metal or dielectric, rough or polished, opaque or clear",
            ),
        ] {
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
    material_fields(ui, &mut object.material, texture_count, &mut choose_texture);
    ui.horizontal(|ui| {
        ui.label("Preset")
            .on_hover_text("Replace the material with a named one");
        egui::ComboBox::from_id_salt("preset")
            .selected_text("choose…")
            .show_ui(ui, |ui| {
                for preset in PRESETS {
                    if ui
                        .selectable_label(false, preset.name)
                        .on_hover_text(preset.tip)
                        .clicked()
                    {
                        object.material = (preset.material)();
                    }
                }
            })
            .response
            .on_hover_text("Replace the material with a named one");
    });

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

    if object != app.doc.scene.objects[index] {
        app.doc.edit(
            &format!("edit {}", object.name),
            &format!("object#{index}"),
            |s| s.objects[index] = object,
        );
    }
    if choose_texture
        && let Some(path) = rfd::FileDialog::new()
            .add_filter("Images", &["png", "jpg", "jpeg", "ppm", "exr"])
            .pick_file()
    {
        app.set_texture_from_file(index, &path);
    }
}

fn vec3_row(ui: &mut Ui, label: &str, v: &mut [f32; 3], speed: f32, tip: &str) {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        for (c, axis) in v.iter_mut().zip(["x", "y", "z"]) {
            ui.add(DragValue::new(c).speed(speed).prefix(format!("{axis} ")))
                .on_hover_text(format!("{label} {axis}"));
        }
    });
}

fn material_fields(ui: &mut Ui, material: &mut Material, textures: usize, choose: &mut bool) {
    match material {
        Material::Lambertian {
            albedo,
            texture: None,
        } => {
            ui.horizontal(|ui| {
                ui.label("Colour");
                ui.color_edit_button_rgb(albedo)
                    .on_hover_text("Diffuse reflectance (albedo)");
            });
        }
        Material::Lambertian {
            texture: Some(t), ..
        } => {
            ui.horizontal(|ui| {
                ui.label("Image");
                egui::ComboBox::from_id_salt("texture")
                    .selected_text(format!("texture {t}"))
                    .show_ui(ui, |ui| {
                        for i in 0..textures {
                            ui.selectable_value(t, i, format!("texture {i}"));
                        }
                    })
                    .response
                    .on_hover_text("Which of the scene's images colours this object");
                if ui
                    .button("Choose image…")
                    .on_hover_text("Load a PNG, JPEG, PPM or EXR image as this object's colour")
                    .clicked()
                {
                    *choose = true;
                }
            });
        }
        Material::Metal { albedo, fuzz } => {
            ui.horizontal(|ui| {
                ui.label("Colour");
                ui.color_edit_button_rgb(albedo)
                    .on_hover_text("Reflectance at normal incidence");
            });
            ui.add(egui::Slider::new(fuzz, 0.0..=1.0).text("fuzz"))
                .on_hover_text("0 is a perfect mirror; 1 is very rough");
        }
        Material::Dielectric { ior, tint } => {
            ui.add(egui::Slider::new(ior, 1.0..=4.0).text("IOR"))
                .on_hover_text("Index of refraction: water 1.333, glass 1.5, diamond 2.417");
            ui.horizontal(|ui| {
                ui.label("Tint");
                ui.color_edit_button_rgb(tint)
                    .on_hover_text("Colour of light passing through");
            });
        }
        Material::Emissive { color, intensity } => {
            ui.horizontal(|ui| {
                ui.label("Colour");
                ui.color_edit_button_rgb(color)
                    .on_hover_text("Colour of the emitted light");
            });
            ui.horizontal(|ui| {
                ui.label("Intensity");
                ui.add(DragValue::new(intensity).speed(0.1).range(0.0..=1e9))
                    .on_hover_text("Emitted radiance = colour × intensity (W/(sr m²) per unit)");
            });
        }
        Material::Pbr(p) => pbr_fields(ui, p, textures, choose),
    }
}

/// A combo choosing one of the scene's images (or none) for a texture slot.
fn texture_slot(
    ui: &mut Ui,
    label: &str,
    id: &str,
    slot: &mut Option<usize>,
    textures: usize,
    tip: &str,
) {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        egui::ComboBox::from_id_salt(id)
            .selected_text(slot.map_or("none".to_string(), |t| format!("texture {t}")))
            .show_ui(ui, |ui| {
                ui.selectable_value(slot, None, "none");
                for i in 0..textures {
                    ui.selectable_value(slot, Some(i), format!("texture {i}"));
                }
            })
            .response
            .on_hover_text(
                "Images load through \"Choose image…\" (base colour) and then can be reused here",
            );
    });
}

/// Every parameter of the physically based material (glTF metallic-roughness).
fn pbr_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize, choose: &mut bool) {
    ui.horizontal(|ui| {
        ui.label("Base colour");
        ui.color_edit_button_rgb(&mut p.base_color)
            .on_hover_text("Diffuse colour of a dielectric, reflectance of a metal");
    });
    ui.horizontal(|ui| {
        let mut textured = p.texture.is_some();
        ui.checkbox(&mut textured, "Image")
            .on_hover_text("Multiply the base colour by one of the scene's images");
        if !textured {
            p.texture = None;
        } else if p.texture.is_none() && textures > 0 {
            p.texture = Some(0);
        }
        if let Some(t) = p.texture.as_mut() {
            egui::ComboBox::from_id_salt("pbr texture")
                .selected_text(format!("texture {t}"))
                .show_ui(ui, |ui| {
                    for i in 0..textures {
                        ui.selectable_value(t, i, format!("texture {i}"));
                    }
                })
                .response
                .on_hover_text("The base colour image");
        }
        if ui
            .button("Choose image…")
            .on_hover_text("Load a PNG, JPEG, PPM or EXR image as the base colour")
            .clicked()
        {
            *choose = true;
        }
    });
    texture_slot(
        ui,
        "Metal/rough image",
        "pbr metallic roughness",
        &mut p.metallic_roughness_texture,
        textures,
        "glTF's packed image: blue scales metallic, green scales roughness (read linearly)",
    );
    texture_slot(
        ui,
        "Normal map",
        "pbr normal map",
        &mut p.normal_texture,
        textures,
        "A tangent-space normal map (+Y up, as glTF); needs vertex normals and UVs",
    );
    if p.normal_texture.is_some() {
        ui.add(egui::Slider::new(&mut p.normal_scale, 0.0..=2.0).text("normal strength"))
            .on_hover_text("Scales the normal map's tilt");
    }
    ui.add(egui::Slider::new(&mut p.metallic, 0.0..=1.0).text("metallic"))
        .on_hover_text("0: plastic, wood, stone; 1: metal");
    ui.add(egui::Slider::new(&mut p.roughness, 0.0..=1.0).text("roughness"))
        .on_hover_text("0 is a mirror; 1 is matte");
    ui.add(egui::Slider::new(&mut p.ior, 1.0..=3.0).text("IOR"))
        .on_hover_text("Index of refraction: water 1.333, glass 1.5, diamond 2.417");
    ui.add(egui::Slider::new(&mut p.transmission, 0.0..=1.0).text("transmission"))
        .on_hover_text("How much light passes through (glass 1)");
    if p.transmission > 0.0 {
        ui.checkbox(&mut p.thin_walled, "thin-walled")
            .on_hover_text("A sheet (a window pane, a leaf): light passes through without bending");
        ui.horizontal(|ui| {
            ui.label("Absorption colour");
            ui.color_edit_button_rgb(&mut p.attenuation_color)
                .on_hover_text(
                    "The colour white light takes after travelling the distance below inside",
                );
        });
        ui.horizontal(|ui| {
            let mut on = p.attenuation_distance.is_some();
            ui.checkbox(&mut on, "at distance")
                .on_hover_text("Without a distance the medium absorbs nothing");
            let mut d = p.attenuation_distance.unwrap_or(1.0);
            if on {
                ui.add(DragValue::new(&mut d).speed(0.01).range(1e-4..=1e6));
            }
            p.attenuation_distance = on.then_some(d);
        });
    }
    ui.horizontal(|ui| {
        ui.label("Emission");
        ui.color_edit_button_rgb(&mut p.emission)
            .on_hover_text("Light the surface gives off, on top of what it reflects");
        ui.add(
            DragValue::new(&mut p.emission_strength)
                .speed(0.1)
                .range(0.0..=1e9),
        )
        .on_hover_text("Emission strength");
    });
    texture_slot(
        ui,
        "Emission image",
        "pbr emission image",
        &mut p.emission_texture,
        textures,
        "An image (sRGB) multiplying the emission: a screen, a lamp's pattern",
    );
    alpha_fields(ui, p);
}

/// glTF's alpha mode: the base colour's alpha cutting holes (leaves, fences) or blending.
fn alpha_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    use rt_core::material::AlphaMode;
    ui.horizontal(|ui| {
        ui.label("Alpha")
            .on_hover_text("How the base colour's alpha (factor × image) cuts the surface");
        egui::ComboBox::from_id_salt("pbr alpha mode")
            .selected_text(format!("{:?}", p.alpha_mode).to_lowercase())
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut p.alpha_mode, AlphaMode::Opaque, "opaque")
                    .on_hover_text("Alpha is ignored");
                ui.selectable_value(&mut p.alpha_mode, AlphaMode::Mask, "mask")
                    .on_hover_text("A hole where alpha is below the cutoff");
                ui.selectable_value(&mut p.alpha_mode, AlphaMode::Blend, "blend")
                    .on_hover_text("See-through in proportion to 1 − alpha");
            })
            .response
            .on_hover_text("The alpha mode");
    });
    if p.alpha_mode != AlphaMode::Opaque {
        ui.add(egui::Slider::new(&mut p.alpha, 0.0..=1.0).text("alpha"))
            .on_hover_text("The base colour factor's alpha");
    }
    if p.alpha_mode == AlphaMode::Mask {
        ui.add(egui::Slider::new(&mut p.alpha_cutoff, 0.0..=1.0).text("alpha cutoff"))
            .on_hover_text("Alpha below this is a hole");
    }
}

pub fn camera_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Camera");
    let mut camera = app.doc.scene.camera.clone();
    let size = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-3));
    let before_from = camera.from;
    vec3_row(
        ui,
        "Position",
        &mut camera.from,
        size * 0.005,
        "Where the camera is",
    );
    if camera.from != before_from {
        // Moving the camera moves its target with it, keeping the view direction.
        let moved = glam::Vec3::from(camera.from) - glam::Vec3::from(before_from);
        camera.to = (glam::Vec3::from(camera.to) + moved).to_array();
    }
    let (mut yaw, mut pitch) = crate::navigation::yaw_pitch_deg(&camera);
    let (yaw0, pitch0) = (yaw, pitch);
    ui.horizontal(|ui| {
        ui.label("Rotation °")
            .on_hover_text("Yaw about the vertical axis and pitch above the horizon, in degrees");
        ui.add(DragValue::new(&mut yaw).speed(0.5).prefix("yaw "))
            .on_hover_text("Yaw in degrees");
        ui.add(
            DragValue::new(&mut pitch)
                .speed(0.5)
                .range(-89.0..=89.0)
                .prefix("pitch "),
        )
        .on_hover_text("Pitch in degrees");
    });
    if yaw != yaw0 || pitch != pitch0 {
        crate::navigation::set_yaw_pitch_deg(&mut camera, yaw, pitch);
    }
    ui.add(egui::Slider::new(&mut camera.vfov_deg, 1.0..=170.0).text("vertical FOV °"))
        .on_hover_text("Vertical field of view in degrees");
    ui.add(
        egui::Slider::new(&mut camera.aperture_radius, 0.0..=size * 0.05)
            .text("aperture")
            .clamping(egui::SliderClamping::Never),
    )
    .on_hover_text("Lens radius in scene units: 0 is a pinhole (all in focus)");
    ui.horizontal(|ui| {
        let mut auto = camera.focus_distance.is_none();
        if ui
            .checkbox(&mut auto, "focus at target")
            .on_hover_text("Focus on the point the camera looks at")
            .changed()
        {
            let distance = glam::Vec3::from(camera.from).distance(glam::Vec3::from(camera.to));
            camera.focus_distance = if auto { None } else { Some(distance) };
        }
        if let Some(d) = &mut camera.focus_distance {
            ui.add(DragValue::new(d).speed(size * 0.005).range(1e-6..=f32::MAX))
                .on_hover_text("Distance to the plane in focus");
        }
    });
    let picking = app.ui.picking_focus;
    if ui
        .selectable_label(picking, "Pick focus point")
        .on_hover_text("Then click in the viewport on what should be sharp")
        .clicked()
    {
        app.ui.picking_focus = !picking;
    }
    ui.horizontal(|ui| {
        if ui
            .button("Frame selection")
            .on_hover_text("Fit the selection (or the scene) in view (F)")
            .clicked()
        {
            app.frame_selection();
        }
        if ui
            .button("Reset view")
            .on_hover_text("The camera the scene was opened with (Home)")
            .clicked()
        {
            app.reset_view();
        }
    });
    ui.checkbox(&mut app.ui.orbit_mode, "Orbit mode")
        .on_hover_text("Right-drag orbits around the selection (O)");
    if camera != app.doc.scene.camera {
        app.doc
            .edit("change camera", "camera", |s| s.camera = camera);
    }
}

/// A setting that is off (`None`) or a number: a checkbox, and the value beside it when on.
struct OptionalSetting {
    label: &'static str,
    tip: &'static str,
    value_tip: &'static str,
    /// The value when the checkbox turns it on.
    default: f32,
    speed: f64,
    range: std::ops::RangeInclusive<f32>,
}

fn optional_setting(ui: &mut Ui, value: &mut Option<f32>, setting: OptionalSetting) {
    ui.horizontal(|ui| {
        let mut on = value.is_some();
        if ui
            .checkbox(&mut on, setting.label)
            .on_hover_text(setting.tip)
            .changed()
        {
            *value = on.then_some(setting.default);
        }
        if let Some(v) = value {
            ui.add(DragValue::new(v).speed(setting.speed).range(setting.range))
                .on_hover_text(setting.value_tip);
        }
    });
}

pub fn render_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Render");
    let mut settings = app.doc.scene.settings.clone();
    egui::Grid::new("render settings").show(ui, |ui| {
        ui.label("Width");
        ui.add(DragValue::new(&mut settings.width).range(1..=rt_core::scene::MAX_IMAGE_SIDE))
            .on_hover_text("Image width in pixels");
        ui.end_row();
        ui.label("Height");
        ui.add(DragValue::new(&mut settings.height).range(1..=rt_core::scene::MAX_IMAGE_SIDE))
            .on_hover_text("Image height in pixels");
        ui.end_row();
        ui.label("Samples/pixel");
        ui.add(DragValue::new(&mut settings.samples_per_pixel).range(1..=1_000_000))
            .on_hover_text("More samples, less noise: noise falls as 1/sqrt(samples)");
        ui.end_row();
        ui.label("Max depth");
        ui.add(DragValue::new(&mut settings.max_depth).range(0..=64))
            .on_hover_text("Ray segments per path: ~5 for diffuse scenes, ~10 with metal or glass");
        ui.end_row();
    });
    if app.doc.has_metal_or_glass() && settings.max_depth < 10 {
        ui.weak("Metal or glass in the scene: a max depth of 10 is recommended.");
    }
    ui.checkbox(&mut settings.next_event_estimation, "Light sampling (NEE)")
        .on_hover_text("Sample lights directly: far less noise with small lights");
    ui.checkbox(&mut settings.russian_roulette, "Russian roulette")
        .on_hover_text("End dim paths early at random (unbiased, faster)");
    ui.horizontal(|ui| {
        use rt_core::math::rng::SamplerKind;
        ui.label("Sampler")
            .on_hover_text("Where the random numbers come from");
        ui.selectable_value(
            &mut settings.sampler,
            SamplerKind::Independent,
            "Independent",
        )
        .on_hover_text("Independent random numbers (PCG)");
        ui.selectable_value(&mut settings.sampler, SamplerKind::Sobol, "Sobol")
            .on_hover_text(
                "Owen-scrambled Sobol points: evenly spread samples, less noise on smooth lighting",
            );
    });
    optional_setting(
        ui,
        &mut settings.clamp,
        OptionalSetting {
            label: "Firefly clamp",
            tip: "Limit each sample's brightness: removes bright speckles at the cost of some \
                  energy (biased; off by default)",
            value_tip: "The most any bounce of light may contribute per colour channel",
            default: 10.0,
            speed: 0.1,
            range: 0.01..=1e6,
        },
    );
    optional_setting(
        ui,
        &mut settings.adaptive_threshold,
        OptionalSetting {
            label: "Adaptive sampling",
            tip: "Stop sampling pixels whose noise is already low (after 16 samples), so the \
                  samples go where the noise is",
            value_tip: "The noise at which a pixel stops: the square root of its relative \
                        mean squared error, e.g. 0.02",
            default: 0.02,
            speed: 0.001,
            range: 0.001..=1.0,
        },
    );
    if settings != app.doc.scene.settings {
        app.doc.edit("change render settings", "settings", |s| {
            s.settings = settings
        });
    }
    ui.horizontal(|ui| {
        if ui
            .button("Render image")
            .on_hover_text("Render an image on a background thread (F12)")
            .clicked()
        {
            app.start_render();
        }
        if ui
            .add_enabled(app.is_rendering(), egui::Button::new("Cancel render"))
            .on_hover_text("Stop rendering and keep the samples so far (Esc)")
            .clicked()
        {
            app.cancel_renders();
        }
    });
    for r in app.renders.iter().filter(|r| r.job.is_running()) {
        let p = r.job.progress;
        let eta = p.eta().map_or("…".to_string(), |d| {
            format!("{:.0} s left", d.as_secs_f32())
        });
        let noise = p
            .noise
            .map_or(String::new(), |n| format!(", noise {:.1}%", n * 100.0));
        ui.add(egui::ProgressBar::new(p.fraction()).text(format!(
            "{}/{} spp, {eta}{noise}",
            p.samples_done, p.samples_total
        )))
        .on_hover_text("Samples per pixel done, estimated time left and relative noise");
    }
}

pub fn status_bar(app: &mut RtApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        ui.label(app.adapter_label())
            .on_hover_text("The GPU (adapter) in use");
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
