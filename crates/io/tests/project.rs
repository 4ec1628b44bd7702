//! Project and lighting files: exact round trips, and a clear error (never a panic or a write) for
//! every kind of bad archive.

#![expect(clippy::unwrap_used, reason = "test helpers fail by panicking")]

use std::io::{Cursor, Write};
use std::path::Path;
use std::sync::Arc;

use rt_core::{Material, Object, Scene, Texture, Transform};
use rt_io::project::{
    self, LIGHTING_FORMAT, Lighting, LoadLimits, PROJECT_FORMAT, decode_archive, encode_archive,
};

fn rich_scene() -> Scene {
    let mut scene = rt_io::assets::cornell_box().unwrap();
    let mut sphere = rt_core::shapes::uv_sphere(50.0, 8, 12);
    sphere.colors = Some(
        (0..sphere.positions.len())
            .map(|i| glam::Vec3::new(i as f32 / 200.0, 0.5, 1.0))
            .collect(),
    );
    let sphere = Arc::new(sphere);
    scene.textures.push(Texture {
        sampler: rt_core::TextureSampler {
            wrap_s: rt_core::Wrap::MirroredRepeat,
            wrap_t: rt_core::Wrap::ClampToEdge,
            filter: rt_core::Filter::Nearest,
        },
        name: "checker.png".into(),
        width: 2,
        height: 2,
        rgba8: vec![
            255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128,
        ]
        .into(),
    });
    scene.objects.push(Object {
        shadow_catcher: true,
        animation_node: None,
        name: "textured ball".into(),
        mesh: sphere.clone(),
        material: Material::Lambertian {
            albedo: [1.0; 3],
            texture: Some(0),
        },
        transform: Transform {
            translation: [100.0, 80.0, 200.0],
            rotation_deg: [10.0, 20.0, 30.0],
            scale: [1.0, 2.0, 0.5],
        },
    });
    scene.objects.push(Object {
        shadow_catcher: false,
        animation_node: None,
        name: "glass ball (same mesh)".into(),
        mesh: sphere,
        material: Material::Dielectric {
            ior: 1.517,
            tint: [0.9, 1.0, 0.95],
        },
        transform: Transform::default(),
    });
    scene.camera.vfov_deg = 33.0;
    scene.camera.aperture_radius = 2.5;
    scene.camera.focus_distance = Some(700.0);
    scene.ambient = [0.1, 0.2, 0.3];
    scene.settings.width = 320;
    scene.settings.height = 200;
    scene.settings.samples_per_pixel = 17;
    scene.settings.max_depth = 11;
    scene.settings.seed = 42;
    scene.settings.next_event_estimation = false;
    scene.settings.clamp = Some(4.0);
    let mut spot = rt_core::Light::new(rt_core::LightKind::Spot, "spot");
    spot.position = [1.0, 2.0, 3.0];
    spot.direction = [0.0, -1.0, 0.5];
    spot.inner_angle_deg = 12.0;
    spot.outer_angle_deg = 40.0;
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.color = [1.0, 0.9, 0.8];
    sun.intensity = 2.5;
    scene.lights = vec![spot, sun];
    let short_block = scene
        .objects
        .iter_mut()
        .find(|o| o.name == "short_block")
        .unwrap();
    short_block.material = Material::Pbr(Box::new(rt_core::material::Pbr {
        base_color: [1.0, 0.766, 0.336],
        texture: Some(0),
        metallic_roughness_texture: Some(0),
        normal_texture: Some(0),
        normal_scale: 0.75,
        metallic: 1.0,
        roughness: 0.35,
        ior: 1.45,
        transmission: 0.25,
        thin_walled: true,
        attenuation_color: [0.5, 0.6, 0.7],
        attenuation_distance: Some(3.0),
        emission: [0.1, 0.2, 0.3],
        emission_strength: 2.0,
        emission_texture: Some(0),
        alpha_mode: rt_core::material::AlphaMode::Mask,
        alpha: 0.8,
        alpha_cutoff: 0.3,
        specular: 0.6,
        specular_color: [1.2, 0.9, 0.5],
        clearcoat: 0.7,
        clearcoat_roughness: 0.15,
        sheen_color: [0.3, 0.2, 0.9],
        sheen_roughness: 0.45,
        clearcoat_texture: Some(0),
        clearcoat_roughness_texture: Some(0),
        sheen_color_texture: Some(0),
        sheen_roughness_texture: Some(0),
        specular_texture: Some(0),
        specular_color_texture: Some(0),
        clearcoat_normal_texture: Some(0),
        clearcoat_normal_scale: 0.5,
        diffuse_transmission: 0.35,
        diffuse_transmission_color: [0.2, 0.9, 0.1],
        iridescence: 0.9,
        iridescence_ior: 1.8,
        iridescence_thickness_min: 50.0,
        iridescence_thickness_max: 700.0,
        anisotropy: 0.55,
        anisotropy_rotation: -1.25,
        anisotropy_texture: Some(0),
        diffuse_transmission_texture: Some(0),
        diffuse_transmission_color_texture: Some(0),
        iridescence_texture: Some(0),
        iridescence_thickness_texture: Some(0),
        dispersion: 0.4,
        multiscatter_color: [0.9, 0.5, 0.2],
        scatter_anisotropy: -0.3,
        subsurface: 0.8,
        subsurface_radius: [0.3, 0.1, 0.05],
    }));
    let (map, _) = rt_core::EnvironmentMap::from_texels(
        3,
        2,
        vec![
            [0.1, 0.2, 0.3],
            [4.0, 5.0, 6.0],
            [0.0; 3],
            [1e-7, 7.5, 1e4],
            [1.0; 3],
            [0.5; 3],
        ],
    );
    let mut env = rt_core::Environment::new("sky.hdr", map);
    env.rotation_deg = -75.5;
    env.strength = 1.25;
    scene.environment = Some(env);
    scene.fog = rt_core::fog::Fog {
        density: 0.35,
        albedo: [0.9, 0.8, 0.7],
        anisotropy: 0.4,
    };
    scene
}

fn path() -> &'static Path {
    Path::new("test.rtproj")
}

fn decode(bytes: &[u8]) -> rt_core::Result<Scene> {
    decode_archive(bytes, path(), PROJECT_FORMAT, &LoadLimits::default())
}

/// A zip with the given (name, bytes) entries, stored uncompressed unless `deflate`.
fn zip_of(entries: &[(&str, &[u8])], deflate: bool) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let method = if deflate {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    for (name, data) in entries {
        zip.start_file(
            *name,
            zip::write::SimpleFileOptions::default().compression_method(method),
        )
        .unwrap();
        zip.write_all(data).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// The entries of an archive, to rebuild it with changes.
fn entries_of(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut file = zip.by_index(i).unwrap();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut file, &mut data).unwrap();
            (file.name().unwrap().to_string(), data)
        })
        .collect()
}

fn with_manifest(bytes: &[u8], edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let mut entries = entries_of(bytes);
    for (name, data) in &mut entries {
        if name == "project.json" {
            let mut json: serde_json::Value = serde_json::from_slice(data).unwrap();
            edit(&mut json);
            *data = serde_json::to_vec(&json).unwrap();
        }
    }
    let refs: Vec<(&str, &[u8])> = entries
        .iter()
        .map(|(n, d)| (n.as_str(), d.as_slice()))
        .collect();
    zip_of(&refs, true)
}

/// A change to an archive's `project.json`.
type ManifestEdit = dyn Fn(&mut serde_json::Value);

fn error_of(bytes: &[u8]) -> String {
    decode(bytes).unwrap_err().to_string()
}

#[test]
fn a_project_round_trips_every_field_through_a_file() {
    let scene = rich_scene();
    let dir = std::env::temp_dir().join(format!("rt-project-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("scene.rtproj");
    project::save_project(&scene, &file).unwrap();
    let loaded = project::load_project(&file).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();

    assert_eq!(loaded.camera, scene.camera);
    assert_eq!(loaded.settings, scene.settings);
    assert_eq!(loaded.ambient, scene.ambient);
    assert_eq!(
        loaded.textures, scene.textures,
        "texture names, sizes and texels"
    );
    assert_eq!(
        loaded.lights, scene.lights,
        "point, spot and directional lights"
    );
    assert_eq!(loaded.objects.len(), scene.objects.len());
    for (a, b) in loaded.objects.iter().zip(&scene.objects) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.material, b.material, "{}", a.name);
        assert_eq!(a.transform, b.transform, "{}", a.name);
        assert_eq!(a.shadow_catcher, b.shadow_catcher, "{}", a.name);
        assert_eq!(a.mesh, b.mesh, "{}", a.name);
    }
    assert_eq!(loaded, scene);
    let n = loaded.objects.len();
    assert!(
        Arc::ptr_eq(&loaded.objects[n - 1].mesh, &loaded.objects[n - 2].mesh),
        "a mesh shared by two objects is stored once and shared again"
    );
}

/// `nee_only` is a diagnostic estimator (tests, `rt-cli --nee-only`), not part of a scene: a project
/// leaves it out and loads with it off, and a file written when projects still held it loads.
#[test]
fn projects_leave_out_the_diagnostic_nee_only() {
    let mut scene = rich_scene();
    scene.settings.nee_only = true;
    scene.settings.clamp = Some(0.1);
    let bytes = encode_archive(&scene, PROJECT_FORMAT, path()).unwrap();
    let (_, manifest) = entries_of(&bytes)
        .into_iter()
        .find(|(name, _)| name == "project.json")
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&manifest).unwrap();
    let settings = &json["settings"];
    assert!(settings.get("nee_only").is_none(), "{settings}");
    assert_eq!(settings["max_depth"], 11, "the other settings are saved");
    assert_eq!(settings["clamp"], 0.1, "as set, not widened: {settings}");
    let loaded = decode(&bytes).unwrap();
    let expected = rt_core::RenderSettings {
        nee_only: false,
        ..scene.settings.clone()
    };
    assert_eq!(loaded.settings, expected);

    let old = with_manifest(&bytes, |j| j["settings"]["nee_only"] = true.into());
    let old = decode(&old).expect("a file that holds nee_only still loads");
    assert_eq!(old.settings, expected, "with nee_only off");
}

/// An environment entry whose size disagrees with its texels is named.
#[test]
fn a_truncated_environment_entry_is_named() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    let entries: Vec<(String, Vec<u8>)> = entries_of(&bytes)
        .into_iter()
        .map(|(name, data)| {
            if name == "environment.bin" {
                (name, data[..data.len() - 4].to_vec())
            } else {
                (name, data)
            }
        })
        .collect();
    let refs: Vec<(&str, &[u8])> = entries
        .iter()
        .map(|(n, d)| (n.as_str(), d.as_slice()))
        .collect();
    let e = error_of(&zip_of(&refs, true));
    assert!(e.contains("environment") && e.contains("3x2"), "{e}");
}

#[test]
fn lighting_files_carry_only_ambient_and_emitters() {
    let scene = rich_scene();
    let lighting = Lighting::of(&scene);
    assert_eq!(lighting.lights.len(), 1, "the Cornell box has one light");
    assert!(lighting.fog.is_on(), "the fog travels with the lighting");
    let dir = std::env::temp_dir().join(format!("rt-lighting-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("studio.rtlight");
    project::save_lighting(&lighting, &file).unwrap();
    let loaded = project::load_lighting(&file).unwrap();
    assert_eq!(loaded, lighting);
    let message = project::load_project(&file).unwrap_err().to_string();
    assert!(message.contains("format is 'rt-lighting'"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();

    let mut other = Scene {
        objects: vec![scene.objects[0].clone()],
        ..Scene::default()
    };
    loaded.apply(&mut other);
    assert_eq!(other.ambient, scene.ambient);
    assert_eq!(other.fog, scene.fog);
    assert_eq!(Lighting::of(&other), lighting);
    assert_eq!(
        other.lights.len(),
        2,
        "delta lights travel with the lighting"
    );
    assert_eq!(other.objects.len(), 2, "non-emissive objects are kept");
}

#[test]
fn truncated_and_garbage_archives_are_errors() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    for len in [0, 10, bytes.len() / 3, bytes.len() / 2, bytes.len() - 1] {
        let message = error_of(&bytes[..len]);
        assert!(message.starts_with("test.rtproj: "), "{message}");
    }
    assert!(error_of(b"PK\x03\x04 definitely not a zip").contains("not a readable"));
}

#[test]
fn wrong_and_future_versions_are_named() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    let future = with_manifest(&bytes, |j| j["version"] = 99.into());
    let message = error_of(&future);
    assert!(
        message.contains("version 99") && message.contains("newer rt"),
        "{message}"
    );
    let version_1 = with_manifest(&bytes, |j| {
        j["version"] = 1.into();
        j.as_object_mut().unwrap().remove("lights");
    });
    let old = decode(&version_1).expect("version 1 files (no lights) still load");
    assert!(old.lights.is_empty());
    let zero = with_manifest(&bytes, |j| j["version"] = 0.into());
    assert!(error_of(&zero).contains("version 0"));
    let lighting = with_manifest(&bytes, |j| j["format"] = LIGHTING_FORMAT.into());
    assert!(error_of(&lighting).contains("expected 'rt-project'"));
    let unknown = with_manifest(&bytes, |j| j["surprise"] = true.into());
    assert!(error_of(&unknown).contains("surprise"));
}

#[test]
fn missing_entries_are_named() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    for missing in ["textures/0.png", "meshes/0.bin", "project.json"] {
        let entries: Vec<(String, Vec<u8>)> = entries_of(&bytes)
            .into_iter()
            .filter(|(n, _)| n != missing)
            .collect();
        let refs: Vec<(&str, &[u8])> = entries
            .iter()
            .map(|(n, d)| (n.as_str(), d.as_slice()))
            .collect();
        let message = error_of(&zip_of(&refs, false));
        assert!(
            message.contains(&format!("entry '{missing}' is missing")),
            "{message}"
        );
    }
}

#[test]
fn path_traversal_entries_are_refused() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    let mut entries = entries_of(&bytes);
    for evil in ["../../evil.sh", "/etc/evil", "meshes/../../evil"] {
        entries.push((evil.to_string(), b"#!/bin/sh\n".to_vec()));
        let refs: Vec<(&str, &[u8])> = entries
            .iter()
            .map(|(n, d)| (n.as_str(), d.as_slice()))
            .collect();
        let message = error_of(&zip_of(&refs, false));
        assert!(
            message.contains(evil) && message.contains("traversal"),
            "{message}"
        );
        entries.pop();
    }
    let pointing_out = with_manifest(&bytes, |j| j["objects"][0]["mesh"] = "../x.bin".into());
    assert!(error_of(&pointing_out).contains("traversal"));
}

#[test]
fn decompression_bombs_are_capped() {
    let zeros = vec![0u8; 4 << 20];
    let bomb = zip_of(&[("project.json", &zeros)], true);
    assert!(bomb.len() < 64 << 10, "the bomb compresses well");
    let limits = LoadLimits {
        max_entry_bytes: 1 << 20,
        ..LoadLimits::default()
    };
    let message = decode_archive(&bomb, path(), PROJECT_FORMAT, &limits)
        .unwrap_err()
        .to_string();
    assert!(message.contains("decompresses to more than"), "{message}");

    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    let limits = LoadLimits {
        max_total_bytes: 2000,
        ..LoadLimits::default()
    };
    let message = decode_archive(&bytes, path(), PROJECT_FORMAT, &limits)
        .unwrap_err()
        .to_string();
    assert!(message.contains("in all"), "{message}");
}

#[test]
fn json_with_wrong_types_or_non_finite_numbers_is_an_error_naming_the_field() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    let cases: Vec<(Box<ManifestEdit>, &str)> = vec![
        (
            Box::new(|j| j["objects"][0]["name"] = 5.into()),
            "invalid type",
        ),
        (
            Box::new(|j| j["settings"]["width"] = (-3).into()),
            "invalid value",
        ),
        (
            Box::new(|j| j["settings"]["width"] = 0.into()),
            "settings: image size",
        ),
        (
            Box::new(|j| j["objects"][1]["transform"]["scale"][0] = 1e39.into()),
            "objects[1]",
        ),
        (
            Box::new(|j| j["camera"]["vfov_deg"] = 1e39.into()),
            "camera",
        ),
        (
            Box::new(|j| {
                j["objects"][0]["material"] =
                    serde_json::json!({"type": "metal", "albedo": [1, 1, 1], "fuzz": 3})
            }),
            "objects[0]",
        ),
        (
            Box::new(|j| {
                let last = j["objects"].as_array().unwrap().len() - 2;
                j["objects"][last]["material"]["texture"] = 7.into();
            }),
            "texture 7 does not exist",
        ),
        (
            Box::new(|j| j["textures"][0]["width"] = 3.into()),
            "textures[0] says 3x2",
        ),
    ];
    for (edit, expected) in cases {
        let message = error_of(&with_manifest(&bytes, edit));
        assert!(
            message.contains(expected) && message.starts_with("test.rtproj: "),
            "expected '{expected}' in: {message}"
        );
    }
    let nan = with_manifest(&bytes, |_| {});
    let mut entries = entries_of(&nan);
    for (name, data) in &mut entries {
        if name == "project.json" {
            let text = String::from_utf8(data.clone()).unwrap();
            *data = text.replacen("33.0", "NaN", 1).into_bytes();
        }
    }
    let refs: Vec<(&str, &[u8])> = entries
        .iter()
        .map(|(n, d)| (n.as_str(), d.as_slice()))
        .collect();
    let message = error_of(&zip_of(&refs, false));
    assert!(
        message.contains("project.json: expected value"),
        "{message}"
    );
}

#[test]
fn a_corrupt_mesh_or_texture_entry_is_named() {
    let bytes = encode_archive(&rich_scene(), PROJECT_FORMAT, path()).unwrap();
    for (target, expected) in [
        ("meshes/0.bin", "meshes/0.bin"),
        ("textures/0.png", "texture"),
    ] {
        let mut entries = entries_of(&bytes);
        for (name, data) in &mut entries {
            if name == target {
                data.truncate(data.len() / 2);
            }
        }
        let refs: Vec<(&str, &[u8])> = entries
            .iter()
            .map(|(n, d)| (n.as_str(), d.as_slice()))
            .collect();
        let message = error_of(&zip_of(&refs, false));
        assert!(message.contains(expected), "{message}");
    }
}

#[test]
fn a_directory_or_missing_file_is_an_error() {
    let message = project::load_project(&std::env::temp_dir())
        .unwrap_err()
        .to_string();
    assert!(message.contains("directory"), "{message}");
    assert!(project::load_project(Path::new("/no/such/file.rtproj")).is_err());
}
