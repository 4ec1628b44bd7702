//! The Khronos glTF Sample Assets that exercise `KHR_materials_*` (their glTF JSON, vendored in
//! `tests/data/khronos-samples`; their buffers and images are not, so each buffer reads as zeros of
//! its declared length and each image as one white texel of its declared type): each loads with
//! no warning about a material extension, and every material extension it uses shows in at least
//! one of its materials. A file that requires an extension rt lacks is refused, naming it.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rt_core::material::Pbr;

/// The warnings logged while the test binary runs (a logger is per process: installed once).
static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct Capture;

static CAPTURE: Capture = Capture;

impl log::Log for Capture {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Warn
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            WARNINGS.lock().unwrap().push(record.args().to_string());
        }
    }
    fn flush(&self) {}
}

fn capture_warnings() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        log::set_logger(&CAPTURE).unwrap();
        log::set_max_level(log::LevelFilter::Warn);
    });
}

fn samples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/khronos-samples")
}

/// One white texel in the format a URI's extension names.
fn placeholder_image(uri: &str) -> Vec<u8> {
    let format = if uri.ends_with(".jpg") || uri.ends_with(".jpeg") {
        image::ImageFormat::Jpeg
    } else {
        image::ImageFormat::Png
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::RgbImage::from_pixel(1, 1, image::Rgb([255, 255, 255]))
        .write_to(&mut bytes, format)
        .unwrap();
    bytes.into_inner()
}

/// Whether material `p` shows extension `ext` (its parameters away from the defaults).
fn shows(p: &Pbr, ext: &str) -> bool {
    let d = Pbr::default();
    match ext {
        "KHR_materials_anisotropy" => p.anisotropy > 0.0 || p.anisotropy_texture.is_some(),
        "KHR_materials_clearcoat" => p.clearcoat > 0.0,
        "KHR_materials_dispersion" => p.dispersion > 0.0,
        "KHR_materials_diffuse_transmission" => p.diffuse_transmission > 0.0,
        "KHR_materials_emissive_strength" => p.emission_strength > 1.0,
        "KHR_materials_ior" => p.ior != d.ior,
        "KHR_materials_iridescence" => p.iridescence > 0.0,
        "KHR_materials_sheen" => p.sheen_color.iter().any(|&c| c > 0.0),
        "KHR_materials_specular" => {
            p.specular != d.specular
                || p.specular_color != d.specular_color
                || p.specular_texture.is_some()
                || p.specular_color_texture.is_some()
        }
        "KHR_materials_transmission" => p.transmission > 0.0,
        "KHR_materials_volume" => !p.thin_walled || p.attenuation_distance.is_some(),
        _ => true,
    }
}

#[test]
fn khronos_sample_assets_load_their_material_extensions_without_warnings() {
    capture_warnings();
    let mut models: Vec<PathBuf> = std::fs::read_dir(samples())
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    models.sort();
    assert!(models.len() >= 20, "{} models vendored", models.len());
    for dir in models {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let path = dir.join(format!("{name}.gltf"));
        let bytes = std::fs::read(&path).unwrap();
        let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        let list = |key: &str| -> Vec<String> {
            json[key]
                .as_array()
                .map(|a| {
                    a.iter()
                        .filter_map(|v| v.as_str().map(String::from))
                        .collect()
                })
                .unwrap_or_default()
        };
        let (used, required) = (list("extensionsUsed"), list("extensionsRequired"));
        let buffers: Vec<(String, usize)> = json["buffers"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|b| {
                Some((
                    b["uri"].as_str()?.to_string(),
                    b["byteLength"].as_u64()? as usize,
                ))
            })
            .collect();
        let read = |p: &Path| -> rt_core::Result<Vec<u8>> {
            let file = p
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            Ok(match buffers.iter().find(|(uri, _)| uri.ends_with(&file)) {
                Some((_, length)) => vec![0; *length],
                None => placeholder_image(&file),
            })
        };
        let loaded = rt_io::gltf::load_gltf_bytes(&bytes, &path, &dir, &read, None);
        if let Some(missing) = required
            .iter()
            .find(|e| !rt_io::gltf::SUPPORTED_EXTENSIONS.contains(&e.as_str()))
        {
            let message = loaded.err().map(|e| e.to_string()).unwrap_or_default();
            assert!(message.contains(missing), "{name}: {message}");
            eprintln!("{name}: refused, requires {missing}");
            continue;
        }
        let scene = loaded.unwrap_or_else(|e| panic!("{name}: {e}"));
        let warnings: Vec<String> = WARNINGS
            .lock()
            .unwrap()
            .iter()
            // KHR_materials_variants (alternative material sets) is not a material model: rt
            // renders the default set and says it ignores the rest.
            .filter(|w| {
                w.contains(&format!("{name}.gltf"))
                    && w.contains("KHR_materials")
                    && !w.contains("KHR_materials_variants")
            })
            .cloned()
            .collect();
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        let materials: Vec<&Pbr> = scene
            .objects
            .iter()
            .filter_map(|o| match &o.material {
                rt_core::Material::Pbr(p) => Some(&**p),
                _ => None,
            })
            .collect();
        // An IOR given as glTF's default (1.5) is indistinguishable from none.
        let default_ior_only = json["materials"].as_array().into_iter().flatten().all(|m| {
            m["extensions"]["KHR_materials_ior"]["ior"]
                .as_f64()
                .is_none_or(|ior| ior == 1.5)
        });
        for ext in used.iter().filter(|e| e.starts_with("KHR_materials_")) {
            if ext == "KHR_materials_variants" || (ext == "KHR_materials_ior" && default_ior_only) {
                continue;
            }
            assert!(
                materials.iter().any(|p| shows(p, ext)),
                "{name}: no material shows {ext}"
            );
        }
        eprintln!("{name}: {} objects, {used:?}", scene.objects.len());
    }
}
