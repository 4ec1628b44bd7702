//! Material editing for the Inspector: one physically based material in sections (base, specular,
//! transmission, subsurface, coat, sheen, thin film, anisotropy, emission, alpha), which every
//! material is shown as; the other kinds (diffuse, texture, metal, glass, emissive) are presets
//! to start from. A material of another kind shows as its physically based equivalent
//! (`as_pbr`) and becomes physically based when a field is changed.

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

/// The physically based material a material of another kind is shown as: a Lambertian is rough
/// with no specular layer (F0 = F90 = 0: what is left is base/π), a glass smooth and transmitting
/// with its tint as base colour, an emitter black without a specular layer and with its emission;
/// a metal's fuzz becomes GGX roughness, which spreads its reflection a little differently.
pub(super) fn as_pbr(material: &Material) -> rt_core::material::Pbr {
    use rt_core::material::Pbr;
    match material {
        Material::Pbr(p) => (**p).clone(),
        Material::Lambertian { albedo, texture } => Pbr {
            base_color: *albedo,
            texture: *texture,
            roughness: 1.0,
            specular: 0.0,
            ..Default::default()
        },
        Material::Metal { albedo, fuzz } => Pbr {
            base_color: *albedo,
            metallic: 1.0,
            roughness: *fuzz,
            ..Default::default()
        },
        Material::Dielectric { ior, tint } => Pbr {
            base_color: *tint,
            ior: *ior,
            roughness: 0.0,
            transmission: 1.0,
            ..Default::default()
        },
        Material::Emissive { color, intensity } => Pbr {
            base_color: [0.0; 3],
            specular: 0.0,
            emission: *color,
            emission_strength: *intensity,
            ..Default::default()
        },
    }
}

/// The sectioned editor over `material`: it stays as it is until a field changes, and then becomes
/// the physically based material the fields describe.
pub(super) fn material_editor(
    ui: &mut Ui,
    material: &mut Material,
    textures: usize,
    choose: &mut bool,
) {
    let mut p = as_pbr(material);
    let before = p.clone();
    pbr_sections(ui, &mut p, textures, choose);
    if differs(&before, &p) {
        *material = Material::Pbr(Box::new(p));
    }
}

/// Whether an edit changed the material: a colour field hands its value back through its own
/// conversion (up to about 1e-5 off), which is no change.
fn differs(a: &rt_core::material::Pbr, b: &rt_core::material::Pbr) -> bool {
    fn apart(a: &serde_json::Value, b: &serde_json::Value) -> bool {
        use serde_json::Value;
        match (a, b) {
            (Value::Number(x), Value::Number(y)) => {
                let (x, y) = (x.as_f64().unwrap_or(0.0), y.as_f64().unwrap_or(0.0));
                (x - y).abs() > 1e-4 * x.abs().max(y.abs()).max(1.0)
            }
            (Value::Array(x), Value::Array(y)) => {
                x.len() != y.len() || x.iter().zip(y).any(|(x, y)| apart(x, y))
            }
            (Value::Object(x), Value::Object(y)) => {
                x.len() != y.len() || x.iter().any(|(k, v)| y.get(k).is_none_or(|w| apart(v, w)))
            }
            _ => a != b,
        }
    }
    match (serde_json::to_value(a), serde_json::to_value(b)) {
        (Ok(a), Ok(b)) => apart(&a, &b),
        _ => a != b,
    }
}

/// A section of the editor: open at first when it holds something other than its defaults.
fn section(ui: &mut Ui, title: &str, open: bool, body: impl FnOnce(&mut Ui)) {
    egui::CollapsingHeader::new(title)
        .default_open(open)
        .show(ui, body);
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

/// Every parameter of the physically based material (glTF metallic-roughness and its
/// `KHR_materials_*` layers), in sections.
fn pbr_sections(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize, choose: &mut bool) {
    let d = rt_core::material::Pbr::default();
    section(ui, "Base", true, |ui| base_fields(ui, p, textures, choose));
    let specular =
        p.specular != d.specular || p.specular_color != d.specular_color || p.ior != d.ior;
    section(ui, "Specular", specular, |ui| specular_fields(ui, p));
    let transmits = p.transmission > 0.0 || p.diffuse_transmission > 0.0;
    section(ui, "Transmission", transmits, |ui| {
        transmission_fields(ui, p)
    });
    if !p.thin_walled {
        section(ui, "Subsurface", p.subsurface > 0.0, |ui| {
            subsurface_fields(ui, p)
        });
    }
    section(ui, "Coat", p.clearcoat > 0.0, |ui| coat_fields(ui, p));
    let sheen = p.sheen_color.iter().any(|&c| c > 0.0);
    section(ui, "Sheen", sheen, |ui| sheen_fields(ui, p));
    section(ui, "Thin film", p.iridescence > 0.0, |ui| {
        film_fields(ui, p)
    });
    section(ui, "Anisotropy", p.anisotropy > 0.0, |ui| {
        anisotropy_fields(ui, p)
    });
    let emits = p.emission_strength > 0.0 && p.emission.iter().any(|&c| c > 0.0);
    section(ui, "Emission", emits, |ui| emission_fields(ui, p, textures));
    let alpha = p.alpha_mode != rt_core::material::AlphaMode::Opaque;
    section(ui, "Alpha", alpha, |ui| alpha_fields(ui, p));
    layer_images(ui, p, textures);
}

/// Base colour (and its image), metallic, roughness and their image, the normal map.
fn base_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize, choose: &mut bool) {
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
    ui.add(egui::Slider::new(&mut p.metallic, 0.0..=1.0).text("metallic"))
        .on_hover_text("0: plastic, wood, stone; 1: metal");
    ui.add(egui::Slider::new(&mut p.roughness, 0.0..=1.0).text("roughness"))
        .on_hover_text("0 is a mirror; 1 is matte");
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
}

/// The dielectric layer: its index of refraction, strength and tint.
fn specular_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    ui.add(egui::Slider::new(&mut p.ior, 1.0..=3.0).text("IOR"))
        .on_hover_text("Index of refraction: water 1.333, glass 1.5, diamond 2.417");
    ui.add(egui::Slider::new(&mut p.specular, 0.0..=1.0).text("specular"))
        .on_hover_text("Scales the non-metal's reflection (1: what the IOR gives; 0: none)");
    ui.horizontal(|ui| {
        ui.label("Specular tint");
        ui.color_edit_button_rgb(&mut p.specular_color)
            .on_hover_text("Tints the non-metal's reflection at normal incidence");
    });
}

/// Light through the surface: refraction with its medium (absorption, scattering, dispersion), and
/// diffuse transmission through thin sheets.
fn transmission_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    ui.add(egui::Slider::new(&mut p.transmission, 0.0..=1.0).text("transmission"))
        .on_hover_text("How much light passes through (glass 1)");
    ui.add(egui::Slider::new(&mut p.diffuse_transmission, 0.0..=1.0).text("diffuse transmission"))
        .on_hover_text("Light through a thin diffuse sheet: leaves, paper, lampshades");
    if p.diffuse_transmission > 0.0 {
        ui.horizontal(|ui| {
            ui.label("Transmitted colour");
            ui.color_edit_button_rgb(&mut p.diffuse_transmission_color)
                .on_hover_text("The colour of the light that comes through");
        });
    }
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
    if p.transmission > 0.0 && !p.thin_walled {
        ui.add(egui::Slider::new(&mut p.dispersion, 0.0..=2.0).text("dispersion"))
            .on_hover_text(
                "Splits white light into colours, as a prism or a diamond does (20 / Abbe number: \
                 crown glass 0.3, flint 0.6, diamond 0.9)",
            );
    }
}

fn emission_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize) {
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
        "An sRGB image multiplying the emission: a screen, a lamp's pattern",
    );
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

/// The clear coat (Blender's Coat; glTF's `KHR_materials_clearcoat`).
fn coat_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    ui.add(egui::Slider::new(&mut p.clearcoat, 0.0..=1.0).text("clear coat"))
        .on_hover_text("A glossy varnish over everything (car paint, lacquered wood)");
    if p.clearcoat > 0.0 {
        ui.add(egui::Slider::new(&mut p.clearcoat_roughness, 0.0..=1.0).text("coat roughness"))
            .on_hover_text("0: a mirror-like varnish; 1: a satin one");
    }
}

/// Sheen (cloth, velvet; `KHR_materials_sheen`).
fn sheen_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    ui.horizontal(|ui| {
        ui.label("Sheen");
        ui.color_edit_button_rgb(&mut p.sheen_color)
            .on_hover_text("The soft rim of cloth and velvet at grazing angles (black: none)");
    });
    if p.sheen_color.iter().any(|&c| c > 0.0) {
        ui.add(egui::Slider::new(&mut p.sheen_roughness, 0.0..=1.0).text("sheen roughness"))
            .on_hover_text("0: a narrow rim; 1: a broad glow");
    }
}

/// A thin film's interference (`KHR_materials_iridescence`; Blender's Thin Film).
fn film_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
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
}

/// A highlight stretched along one direction (`KHR_materials_anisotropy`; Blender's Anisotropic).
fn anisotropy_fields(ui: &mut Ui, p: &mut rt_core::material::Pbr) {
    ui.add(egui::Slider::new(&mut p.anisotropy, 0.0..=1.0).text("anisotropy"))
        .on_hover_text("Stretches the highlight along one direction: brushed metal, satin, hair");
    if p.anisotropy > 0.0 {
        ui.horizontal(|ui| {
            ui.label("Direction");
            ui.drag_angle(&mut p.anisotropy_rotation)
                .on_hover_text("The direction the highlight stretches, from the mesh's tangent");
        });
    }
}

/// The layers' images, as glTF packs them.
fn layer_images(ui: &mut Ui, p: &mut rt_core::material::Pbr, textures: usize) {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A colour handed back a rounding off is no edit; a real change is.
    #[test]
    fn only_real_edits_convert_a_material() {
        let a = rt_core::material::Pbr::default();
        let mut b = a.clone();
        b.base_color[0] += 1e-7;
        assert!(!differs(&a, &b));
        b.roughness += 0.01;
        assert!(differs(&a, &b));
        let mut c = a.clone();
        c.texture = Some(0);
        assert!(differs(&a, &c));
    }

    /// The kinds map onto the physically based material with their colours.
    #[test]
    fn other_kinds_show_as_their_physically_based_equivalents() {
        let p = as_pbr(&Material::lambertian([0.2, 0.3, 0.4]));
        assert_eq!(
            (p.base_color, p.specular, p.metallic),
            ([0.2, 0.3, 0.4], 0.0, 0.0)
        );
        let p = as_pbr(&Material::Metal {
            albedo: [0.9, 0.6, 0.2],
            fuzz: 0.3,
        });
        assert_eq!((p.metallic, p.roughness), (1.0, 0.3));
        let p = as_pbr(&Material::Dielectric {
            ior: 1.33,
            tint: [0.9; 3],
        });
        assert_eq!((p.transmission, p.ior, p.roughness), (1.0, 1.33, 0.0));
        let p = as_pbr(&Material::Emissive {
            color: [1.0, 0.5, 0.2],
            intensity: 7.0,
        });
        assert_eq!(
            (p.emission, p.emission_strength, p.base_color),
            ([1.0, 0.5, 0.2], 7.0, [0.0; 3])
        );
    }
}
