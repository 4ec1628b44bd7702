//! rt's participating media against Mitsuba 3's `volpath`: the glTF scene and the 4096-spp
//! references in `tests/data/mitsuba-media/` come from `bench/mitsuba-media.py`, whose header lists
//! the media matched (a chromatic scattering ball and a forward-scattering slab behind
//! index-matched boundaries, from `KHR_materials_volume` and the draft
//! `KHR_materials_volume_scatter`; then the same in fog). rt's image must have every channel's
//! mean within 2% of Mitsuba's, 95% of its 32-pixel blocks within 5%, and each object's own pixels
//! within 5%.

mod common;

use std::path::Path;

use common::*;

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

fn media_scene() -> rt_core::Scene {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mitsuba-media");
    let mut scene = rt_io::gltf::load_gltf(&data.join("scene.gltf"), None).unwrap();
    scene.camera.from = [0.0, 1.5, 4.2];
    scene.camera.to = [0.0, 0.45, 0.0];
    scene.camera.up = [0.0, 1.0, 0.0];
    scene.camera.vfov_deg = 35.0;
    scene.ambient = [0.0; 3];
    scene.settings = settings(WIDTH, HEIGHT, 64, 64);
    // The dense ball in front as rt's subsurface scattering (base colour, radius) rather than the
    // glTF's volume: the same medium behind the same boundary, which Mitsuba's reference has.
    let skin = scene
        .objects
        .iter_mut()
        .find(|o| o.name == "skin")
        .expect("the subsurface ball");
    let from_gltf = skin.material.clone();
    skin.material = pbr(rt_core::material::Pbr {
        base_color: [0.9, 0.6, 0.45],
        roughness: 0.0,
        ior: 1.4,
        subsurface: 1.0,
        subsurface_radius: [0.2, 0.12, 0.08],
        ..Default::default()
    });
    let medium = |m: &rt_core::Material| {
        rt_core::GpuScene::build(&scene_with(m.clone()))
            .unwrap()
            .materials[0]
            .medium
    };
    let (a, b) = (medium(&from_gltf), medium(&skin.material));
    for c in 0..3 {
        assert!(
            (a.sigma_t[c] / b.sigma_t[c] - 1.0).abs() < 1e-4
                && (a.sigma_s[c] / b.sigma_s[c] - 1.0).abs() < 1e-4,
            "subsurface {b:?} vs the glTF volume {a:?}"
        );
    }
    scene
}

/// A scene of one small quad of material `m`.
fn scene_with(m: rt_core::Material) -> rt_core::Scene {
    rt_core::Scene {
        objects: vec![object(
            "probe",
            rt_core::shapes::quad(glam::Vec3::ZERO, glam::Vec3::Z, 1.0),
            m,
        )],
        ..Default::default()
    }
}

fn assert_matches_mitsuba(scene: &rt_core::Scene, reference: &str) {
    let Some(ctx) = gpu() else { return };
    let image = render(ctx, scene);
    let reference = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mitsuba-media")
        .join(reference);
    assert_matches_reference(&image, &reference, "Mitsuba volpath", 0.02, 0.05);
    assert_objects_match(scene, &image, &reference, "Mitsuba", 0.05);
}

#[test]
fn scattering_volumes_match_mitsuba_volpath() {
    let scene = media_scene();
    assert!(
        scene
            .objects
            .iter()
            .filter(|o| matches!(&o.material, rt_core::Material::Pbr(p)
                if p.multiscatter_color != [0.0; 3] && !p.thin_walled))
            .count()
            == 2,
        "the glTF's volumes lost their scattering"
    );
    // More samples than in fog: the floor's dim far corners (lit only through the volumes' edges)
    // are 32-px blocks of their own.
    let mut scene = scene;
    scene.settings.samples_per_pixel = 256;
    assert_matches_mitsuba(&scene, "reference.exr");
}

#[test]
fn volumes_in_fog_match_mitsuba_volpath() {
    let mut scene = media_scene();
    scene.fog = rt_core::fog::Fog {
        density: 0.15,
        albedo: [1.0; 3],
        anisotropy: 0.3,
    };
    assert_matches_mitsuba(&scene, "reference-fog.exr");
}
