//! Material editing for the Inspector: the material kinds, switching between them, and the fields
//! of each kind (the physically based material's textures and alpha included).

use egui::{DragValue, Ui};
use rt_core::{Material, MaterialKind};

/// An entry of the inspector's kind list: a material kind and, for a Lambertian one, whether its
/// colour is an image (the list offers "Diffuse" and "Texture").
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) struct Kind {
    pub kind: MaterialKind,
    pub textured: bool,
}

/// The kinds the inspector offers, with their labels and tooltips: `MaterialKind::ALL`, with a
/// textured Lambertian entry after the plain one.
pub(super) fn kind_list() -> Vec<(Kind, &'static str, &'static str)> {
    let mut list = Vec::new();
    for kind in MaterialKind::ALL {
        let entry = Kind {
            kind,
            textured: false,
        };
        list.push((entry, kind.label(), kind.summary()));
        if kind == MaterialKind::Lambertian {
            list.push((
                Kind {
                    kind,
                    textured: true,
                },
                "Texture",
                "Lambertian with an image as its colour",
            ));
        }
    }
    list
}

pub(super) fn kind_of(m: &Material) -> Kind {
    Kind {
        kind: m.kind(),
        textured: matches!(
            m,
            Material::Lambertian {
                texture: Some(_),
                ..
            }
        ),
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

pub(super) fn with_kind(m: &Material, kind: Kind, textures: usize) -> Material {
    let color = color_of(m);
    match kind.kind {
        MaterialKind::Lambertian if !kind.textured => Material::lambertian(color),
        // A texture slot without an image renders white until an image is chosen.
        MaterialKind::Lambertian => Material::Lambertian {
            albedo: [1.0; 3],
            texture: (textures > 0).then_some(0),
        },
        MaterialKind::Metal => Material::Metal {
            albedo: color,
            fuzz: 0.1,
        },
        MaterialKind::Dielectric => Material::Dielectric {
            ior: 1.5,
            tint: [1.0; 3],
        },
        MaterialKind::Emissive => Material::Emissive {
            color,
            intensity: 10.0,
        },
        MaterialKind::Pbr => Material::Pbr(Box::new(rt_core::material::Pbr {
            base_color: color,
            ..Default::default()
        })),
    }
}

pub(super) fn material_fields(
    ui: &mut Ui,
    material: &mut Material,
    textures: usize,
    choose: &mut bool,
) {
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
    if p.transmission > 0.0 || p.diffuse_transmission > 0.0 {
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
        if !p.thin_walled && p.attenuation_distance.is_some() {
            ui.horizontal(|ui| {
                ui.label("Scattering colour");
                ui.color_edit_button_rgb(&mut p.multiscatter_color)
                    .on_hover_text(
                        "The colour a thick piece takes as light scatters inside it (milk, jade, wax); black: \
                         clear, absorbing only",
                    );
            });
            if p.multiscatter_color != [0.0; 3] {
                ui.add(
                    egui::Slider::new(&mut p.scatter_anisotropy, -0.95..=0.95)
                        .text("scatter forward"),
                )
                .on_hover_text("How much the inside scatters light onward rather than back");
            }
        }
    }
    subsurface_fields(ui, p);
    layer_fields(ui, p, textures);
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

/// Subsurface scattering (Blender's Subsurface Weight and Radius): its weight and, when on, how far
/// light travels inside per colour.
fn subsurface_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    if p.thin_walled {
        return;
    }
    ui.add(egui::Slider::new(&mut p.subsurface, 0.0..=1.0).text("subsurface"))
        .on_hover_text(
            "Light entering the surface and scattering inside before it leaves (skin, wax, \
             marble, milk); the base colour becomes the colour inside. Needs a closed mesh",
        );
    if p.subsurface > 0.0 {
        ui.horizontal(|ui| {
            ui.label("radius").on_hover_text(
                "How far light travels inside between scatterings, for red, green and blue, in \
                 scene units",
            );
            for (r, channel) in p.subsurface_radius.iter_mut().zip(["R", "G", "B"]) {
                ui.add(
                    DragValue::new(r)
                        .speed(0.001)
                        .range(1e-5..=1e6)
                        .prefix(format!("{channel} ")),
                );
            }
        });
    }
}

/// The dielectric's specular strength and tint, the clear coat, the sheen, the diffuse
/// transmission, the thin film and the anisotropy (glTF's `KHR_materials_*`; Blender's Specular,
/// Coat, Sheen, Transmission, Thin Film and Anisotropic).
fn layer_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize) {
    ui.add(egui::Slider::new(&mut p.specular, 0.0..=1.0).text("specular"))
        .on_hover_text("Scales the non-metal's reflection (1: what the IOR gives; 0: none)");
    ui.horizontal(|ui| {
        ui.label("Specular tint");
        ui.color_edit_button_rgb(&mut p.specular_color)
            .on_hover_text("Tints the non-metal's reflection at normal incidence");
    });
    ui.add(egui::Slider::new(&mut p.clearcoat, 0.0..=1.0).text("clear coat"))
        .on_hover_text("A glossy varnish over everything (car paint, lacquered wood)");
    if p.clearcoat > 0.0 {
        ui.add(egui::Slider::new(&mut p.clearcoat_roughness, 0.0..=1.0).text("coat roughness"))
            .on_hover_text("0: a mirror-like varnish; 1: a satin one");
    }
    ui.horizontal(|ui| {
        ui.label("Sheen");
        ui.color_edit_button_rgb(&mut p.sheen_color)
            .on_hover_text("The soft rim of cloth and velvet at grazing angles (black: none)");
    });
    if p.sheen_color.iter().any(|&c| c > 0.0) {
        ui.add(egui::Slider::new(&mut p.sheen_roughness, 0.0..=1.0).text("sheen roughness"))
            .on_hover_text("0: a narrow rim; 1: a broad glow");
    }
    ui.add(egui::Slider::new(&mut p.diffuse_transmission, 0.0..=1.0).text("diffuse transmission"))
        .on_hover_text("Light through a thin diffuse sheet: leaves, paper, lampshades");
    if p.diffuse_transmission > 0.0 {
        ui.horizontal(|ui| {
            ui.label("Transmitted colour");
            ui.color_edit_button_rgb(&mut p.diffuse_transmission_color)
                .on_hover_text("The colour of the light that comes through");
        });
    }
    ui.add(egui::Slider::new(&mut p.iridescence, 0.0..=1.0).text("iridescence"))
        .on_hover_text("A thin film's rainbow: soap bubbles, oil on water, anodised metal");
    if p.iridescence > 0.0 {
        ui.add(egui::Slider::new(&mut p.iridescence_ior, 1.0..=3.0).text("film IOR"))
            .on_hover_text("The film's index of refraction (soap 1.33, oil 1.5)");
        ui.add(
            egui::Slider::new(&mut p.iridescence_thickness_max, 0.0..=1200.0)
                .text("film thickness (nm)"),
        )
        .on_hover_text("Thicker films cycle through more colours");
        if p.iridescence_thickness_texture.is_some() {
            ui.add(
                egui::Slider::new(&mut p.iridescence_thickness_min, 0.0..=1200.0)
                    .text("thinnest film (nm)"),
            )
            .on_hover_text("The thickness where the film thickness image is black");
        }
    }
    if p.transmission > 0.0 && !p.thin_walled {
        ui.add(egui::Slider::new(&mut p.dispersion, 0.0..=2.0).text("dispersion"))
            .on_hover_text(
                "Splits white light into colours, as a prism or a diamond does (20 / Abbe number: \
                 crown glass 0.3, flint 0.6, diamond 0.9)",
            );
    }
    ui.add(egui::Slider::new(&mut p.anisotropy, 0.0..=1.0).text("anisotropy"))
        .on_hover_text("Stretches the highlight along one direction: brushed metal, satin, hair");
    if p.anisotropy > 0.0 {
        ui.horizontal(|ui| {
            ui.label("Direction");
            ui.drag_angle(&mut p.anisotropy_rotation)
                .on_hover_text("The direction the highlight stretches, from the mesh's tangent");
        });
    }
    // The layers' images, as glTF packs them.
    ui.collapsing("Layer images", |ui| {
        for (label, id, slot, hover) in [
            (
                "Specular image",
                "pbr specular image",
                &mut p.specular_texture,
                "Its alpha scales the specular strength",
            ),
            (
                "Specular tint image",
                "pbr specular tint image",
                &mut p.specular_color_texture,
                "An sRGB image tinting the specular colour",
            ),
            (
                "Coat image",
                "pbr coat image",
                &mut p.clearcoat_texture,
                "Its red channel scales the clear coat",
            ),
            (
                "Coat roughness image",
                "pbr coat roughness image",
                &mut p.clearcoat_roughness_texture,
                "Its green channel scales the coat's roughness",
            ),
            (
                "Coat normal map",
                "pbr coat normal map",
                &mut p.clearcoat_normal_texture,
                "The coat's own bumps (tangent space); without one the coat stays smooth over \
                 the base's normal map",
            ),
            (
                "Sheen image",
                "pbr sheen image",
                &mut p.sheen_color_texture,
                "An sRGB image multiplying the sheen colour",
            ),
            (
                "Sheen roughness image",
                "pbr sheen roughness image",
                &mut p.sheen_roughness_texture,
                "Its alpha scales the sheen's roughness",
            ),
            (
                "Anisotropy image",
                "pbr anisotropy image",
                &mut p.anisotropy_texture,
                "Red and green: the direction of the stretch in tangent space; blue scales it",
            ),
            (
                "Diffuse transmission image",
                "pbr diffuse transmission image",
                &mut p.diffuse_transmission_texture,
                "Its alpha scales the diffuse transmission",
            ),
            (
                "Transmitted colour image",
                "pbr diffuse transmission colour image",
                &mut p.diffuse_transmission_color_texture,
                "An sRGB image multiplying the transmitted colour",
            ),
            (
                "Film image",
                "pbr iridescence image",
                &mut p.iridescence_texture,
                "Its red channel scales the iridescence",
            ),
            (
                "Film thickness image",
                "pbr iridescence thickness image",
                &mut p.iridescence_thickness_texture,
                "Its green channel picks the film's thickness between the minimum and the maximum",
            ),
        ] {
            texture_slot(ui, label, id, slot, textures, hover);
        }
    });
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
