//! The clear coat, the sheen, `KHR_materials_specular`, the thin film and anisotropy against
//! Blender Cycles: `bench/cycles-layers.py` built a row of Principled spheres in Blender (a plain
//! plastic, the same plastic under a clear coat, a specular-tinted dielectric at 70% specular
//! strength, a velvet with a sheen, a coated steel, a dark dielectric under a 400 nm soap film, a
//! steel brushed along its UV tangents), exported `scene.glb` with Blender's glTF exporter (which
//! writes the coat, sheen, specular and anisotropy; the script adds the film as
//! `KHR_materials_iridescence` and sets the brushed steel's glTF roughness and strength to the GGX
//! widths Cycles gives its Anisotropic) and rendered Cycles' 1024-spp `reference.exr` under a
//! uniform grey world and a sun (the script's header says what was matched). rt renders the .glb
//! under the same ambient radiance: every channel's mean within 2% of Cycles', each object's
//! pixels, per channel, within 5%, and the brushed steel's highlight tile by tile within 6% of
//! Cycles' shape — except the velvet, whose sheen Cycles models with Zeltner's microfibres where
//! glTF specifies Charlie's distribution (measured +18% red, +15% green, +1% blue at 1024 spp
//! both; docs/quality.md; it must stay within 25%), and the brushed steel's mean, which rt's own
//! anisotropic albedo table brightens by 6% over Cycles' mean-width lookup (within 9%).

mod common;

use std::path::Path;

use common::*;

#[test]
fn coat_sheen_and_specular_render_as_cycles_renders_them() {
    let Some(ctx) = gpu() else { return };
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cycles-layers");
    let mut scene = rt_io::gltf::load_gltf(&data.join("scene.glb"), None).unwrap();
    let layered = |name: &str| {
        let o = scene.objects.iter().find(|o| o.name == name).unwrap();
        let rt_core::Material::Pbr(p) = &o.material else {
            panic!("{name}: PBR expected")
        };
        (
            p.clearcoat,
            p.sheen_color,
            p.specular,
            p.iridescence,
            p.anisotropy,
        )
    };
    assert_eq!(layered("coated").0, 1.0, "the coat comes through");
    assert_eq!(
        layered("velvet").1,
        [1.0, 0.8, 0.6],
        "the sheen comes through"
    );
    assert!(
        (layered("specular").2 - 0.7).abs() < 1e-6,
        "the specular comes through"
    );
    assert_eq!(layered("soap film").3, 1.0, "the film comes through");
    assert!(
        layered("brushed steel").4 > 0.5,
        "the anisotropy comes through"
    );
    scene.environment = None;
    scene.ambient = [0.5; 3];
    scene.settings = settings(448, 128, 256, 8);
    let image = render(ctx, &scene);
    let reference = data.join("reference.exr");
    assert_matches_reference(&image, &reference, "Cycles", 0.02, 0.08);
    assert_objects_match(&scene, &image, &reference, |name| match name {
        "velvet" => 0.25,
        // rt restores the energy a stretched lobe's multiple scattering keeps from its own
        // table (`math::anisotropic_energy`); Cycles reads its isotropic table at the mean
        // width, which does not: +6.3% measured (-0.6% when rt did the same).
        "brushed steel" => 0.09,
        _ => 0.05,
    });
    // The brushed steel's mean is that of an isotropic steel too (+0.1% measured): its highlight's
    // shape is the test. Each 8 × 8-pixel tile at least half covered by it, relative to the
    // sphere's whole (the compensation's difference above), within 6% of Cycles (measured worst
    // 4.0% at 256 spp; the steel rendered isotropic, anisotropy ignored, is off by up to 62%, 15%
    // in the median tile).
    let steel = scene
        .objects
        .iter()
        .position(|o| o.name == "brushed steel")
        .unwrap();
    let (all_ours, all_theirs, _) = object_sums(&scene, &image, &reference)[steel];
    let whole = all_ours.iter().sum::<f64>() / all_theirs.iter().sum::<f64>();
    let tiles = object_tile_sums(&scene, &image, &reference, "brushed steel", 8);
    let mut checked = 0;
    let mut worst = 0.0f64;
    for (k, (ours, theirs, pixels)) in tiles.iter().enumerate() {
        if *pixels < 32 {
            continue;
        }
        checked += 1;
        let difference = ours.iter().sum::<f64>() / theirs.iter().sum::<f64>() / whole - 1.0;
        worst = worst.max(difference.abs());
        assert!(
            difference.abs() <= 0.06,
            "brushed steel, tile {k} ({pixels} pixels): rt's shape differs from Cycles' by {:+.1}%",
            100.0 * difference
        );
    }
    eprintln!(
        "brushed steel: {checked} tiles, worst {:.1}% from Cycles' shape",
        100.0 * worst
    );
    assert!(checked >= 20, "only {checked} tiles of brushed steel");
}

/// Each object's pixels, per channel, within `tolerance(name)` of Cycles' (relative).
fn assert_objects_match(
    scene: &rt_core::Scene,
    image: &rt_gpu::Image,
    reference: &Path,
    tolerance: impl Fn(&str) -> f64,
) {
    for (object, (ours, theirs, pixels)) in scene
        .objects
        .iter()
        .zip(object_sums(scene, image, reference))
    {
        let tolerance = tolerance(&object.name);
        for c in 0..3 {
            let difference = ours[c] / theirs[c] - 1.0;
            eprintln!(
                "{} channel {c}: {pixels} pixels, rt/Cycles {:+.2}%",
                object.name,
                100.0 * difference
            );
            assert!(
                difference.abs() <= tolerance,
                "{} channel {c}: rt differs from Cycles by {:+.2}% over its {pixels} pixels",
                object.name,
                100.0 * difference
            );
        }
    }
}

/// Smooth and rough glass against Cycles: `bench/cycles-layers.py --set glass` built a row of solid
/// Principled glass spheres (roughness 0, 0.2, 0.4 and 0.7 at IOR 1.5; a tinted rough glass at
/// 1.45; rough water, 1.33; a rough dense glass, 1.8), exported them (the script makes each a solid
/// with KHR_materials_volume) and rendered Cycles' 1024-spp reference under the same grey world
/// and sun as the layers. Cycles compensates rough glass's multiple scattering with its
/// `ggx_glass_E` tables, rt with its own (`math::glass_energy`); both take the sun through the
/// rough glass by next-event estimation from its far side (without that rt was 8–16% darker on
/// the rough spheres). Each untinted object within 5% (measured −1.3% to −3.3% at 1024 spp, the
/// floor −1.5%), the image mean within 3% (−1.8%). The tinted glass follows each renderer's
/// convention: rt tints transmitted light by the base colour at each crossing of the surface (glTF's
/// BTDF, `specular_btdf · baseColor`, at every interface, as MaterialX squares the tint of a
/// two-sided refraction), Cycles' Principled BSDF gives a solid its base colour once. So rt renders
/// it with the square root of Cycles' colour, which gives a solid the same colour through two
/// crossings, and is held to 5% like the rest (with Cycles' colour as it is, it was −12%, −45%,
/// −57% darker for 0.9, 0.5, 0.3; docs/quality.md).
#[test]
fn rough_glass_renders_as_cycles_renders_it() {
    let Some(ctx) = gpu() else { return };
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cycles-glass");
    let mut scene = rt_io::gltf::load_gltf(&data.join("scene.glb"), None).unwrap();
    for o in scene.objects.iter().filter(|o| o.name != "floor") {
        let rt_core::Material::Pbr(p) = &o.material else {
            panic!("{}: PBR expected", o.name)
        };
        assert!(
            p.transmission == 1.0 && !p.thin_walled,
            "{}: a solid glass expected",
            o.name
        );
    }
    for o in &mut scene.objects {
        if let rt_core::Material::Pbr(p) = &mut o.material
            && o.name == "tinted rough glass"
        {
            p.base_color = p.base_color.map(f32::sqrt);
        }
    }
    scene.environment = None;
    scene.ambient = [0.5; 3];
    scene.settings = settings(448, 128, 256, 8);
    let image = render(ctx, &scene);
    let reference = data.join("reference.exr");
    assert_matches_reference(&image, &reference, "Cycles", 0.03, 0.2);
    assert_objects_match(&scene, &image, &reference, |_| 0.05);
}
