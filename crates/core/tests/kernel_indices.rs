#![allow(clippy::unwrap_used)]
//! `GpuScene::check_kernel_indices`, the index invariants the tracing kernels rely on: every scene
//! rt builds passes it, and each kind of bad index fails it.

use rt_core::GpuScene;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::gpu_types::NO_TEXTURE;
use rt_io::obj::load_obj;
use std::path::Path;

fn shipped_scenes() -> Vec<(String, rt_core::Scene)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let mut out = vec![("cornell".to_string(), rt_io::assets::cornell_box().unwrap())];
    for obj in [
        "bunny/bunny-lowres-npm.obj",
        "spot/spot_triangulated_textured.obj",
    ] {
        out.push((obj.to_string(), load_obj(&root.join(obj), 0).unwrap()));
    }
    out
}

#[test]
fn every_shipped_scene_and_bvh_preset_passes() {
    for (name, scene) in shipped_scenes() {
        for quality in [
            BvhQuality::Fastest,
            BvhQuality::Fast,
            BvhQuality::Medium,
            BvhQuality::Slow,
        ] {
            for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
                let built = GpuScene::build_with_layout(&scene, quality, layout).unwrap();
                built
                    .check_kernel_indices()
                    .unwrap_or_else(|e| panic!("{name} {quality:?} {layout:?}: {e}"));
            }
        }
    }
    let empty = rt_core::Scene::default();
    for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
        GpuScene::build_with_layout(&empty, BvhQuality::default(), layout)
            .unwrap()
            .check_kernel_indices()
            .unwrap();
    }
}

fn build(scene: &rt_core::Scene, layout: BvhLayout) -> GpuScene {
    GpuScene::build_with_layout(scene, BvhQuality::default(), layout).unwrap()
}

#[test]
fn each_kind_of_bad_wide_bvh_index_is_caught() {
    let good = build(&shipped_scenes()[1].1, BvhLayout::Cwbvh);
    good.check_kernel_indices().unwrap();
    let imask = |n: &rt_core::gpu_types::WideBvhNode| n.exponents_imask >> 24;
    let inner = good
        .wide_nodes
        .iter()
        .position(|n| imask(n) != 0)
        .expect("a node with inner children");
    let (leaf, slot) = good
        .wide_nodes
        .iter()
        .enumerate()
        .find_map(|(i, n)| {
            (0..8).find_map(|slot| {
                let meta = (n.slots[slot / 4] >> (slot % 4 * 8)) & 0xff;
                (imask(n) & (1 << slot) == 0 && meta != 0).then_some((i, slot))
            })
        })
        .expect("a leaf slot");
    let set_meta = |s: &mut GpuScene, node: usize, slot: usize, meta: u32| {
        let word = &mut s.wide_nodes[node].slots[slot / 4];
        *word = (*word & !(0xff << (slot % 4 * 8))) | (meta << (slot % 4 * 8));
    };
    let cases: Vec<(&str, GpuScene)> = vec![
        ("inner children pointing backwards (a cycle)", {
            let mut s = good.clone();
            s.wide_nodes[inner].child_base = inner as u32;
            s
        }),
        ("inner children past the nodes", {
            let mut s = good.clone();
            s.wide_nodes[inner].child_base = s.wide_nodes.len() as u32 - 1;
            s
        }),
        ("leaf past the triangles", {
            let mut s = good.clone();
            s.wide_nodes[leaf].primitive_base = s.triangles.len() as u32;
            s
        }),
        ("leaf bits reaching the inner children's bits", {
            let mut s = good.clone();
            set_meta(&mut s, leaf, slot, 0b011_10111); // two triangles from offset 23
            s
        }),
        ("leaf count not unary", {
            let mut s = good.clone();
            set_meta(&mut s, leaf, slot, 0b101_00000);
            s
        }),
        ("inner slot with a leaf's byte", {
            let mut s = good.clone();
            let slot = (0..8).find(|b| imask(&s.wide_nodes[inner]) & (1 << b) != 0);
            set_meta(&mut s, inner, slot.unwrap(), 0b001_00000);
            s
        }),
        ("no root", {
            let mut s = good.clone();
            s.wide_nodes.clear();
            s
        }),
    ];
    for (what, scene) in cases {
        assert!(
            scene.check_kernel_indices().is_err(),
            "{what} was not caught"
        );
    }
}

#[test]
fn each_kind_of_bad_index_is_caught() {
    let spot = &shipped_scenes()[2].1;
    let good = build(spot, BvhLayout::Bvh2);
    assert!(good.features.textures && !good.shading.is_empty());
    let cornell = build(&rt_io::assets::cornell_box().unwrap(), BvhLayout::Bvh2);
    assert!(!cornell.emitters.is_empty());
    // An inner node below the root (child index 0 means "no child", so the root cannot show a cycle).
    let inner = good
        .nodes
        .iter()
        .enumerate()
        .skip(1)
        .find(|(_, n)| n.left_count == 0)
        .expect("an inner node below the root")
        .0;
    let leaf = good
        .nodes
        .iter()
        .position(|n| n.left_count > 0)
        .expect("a leaf");
    let cases: Vec<(&str, GpuScene)> = vec![
        ("child pointing backwards (a cycle)", {
            let mut s = good.clone();
            s.nodes[inner].left = inner as u32;
            s
        }),
        ("child past the nodes", {
            let mut s = good.clone();
            s.nodes[inner].left = s.nodes.len() as u32;
            s
        }),
        ("leaf past the triangles", {
            let mut s = good.clone();
            s.nodes[leaf].left = s.triangles.len() as u32 - s.nodes[leaf].left_count + 1;
            s
        }),
        ("material past the materials", {
            let mut s = good.clone();
            s.triangles[0].material = s.materials.len() as u32;
            s
        }),
        ("missing shading record", {
            let mut s = good.clone();
            s.shading.truncate(1);
            s
        }),
        ("vertex record past the shading words", {
            let mut s = good.clone();
            s.shading[2] = s.shading.len() as u32 - 3;
            s
        }),
        ("corner pointing into the corner words", {
            let mut s = good.clone();
            s.shading[1] = 0;
            s
        }),
        ("texture past the texels", {
            with_textured_material(&good, |m| m.textures[0].offset = 1)
        }),
        ("empty texture", {
            with_textured_material(&good, |m| m.textures[0].width = 0)
        }),
        ("emitter alias past the table", {
            let mut s = cornell.clone();
            s.emitters[0].alias_index = s.emitters.len() as u32;
            s
        }),
        ("emitter triangle past the triangles", {
            let mut s = cornell.clone();
            s.emitters[0].triangle = s.triangles.len() as u32;
            s
        }),
        ("no root", {
            let mut s = cornell.clone();
            s.nodes.clear();
            s
        }),
    ];
    for (what, scene) in cases {
        assert!(
            scene.check_kernel_indices().is_err(),
            "{what} was not caught"
        );
    }
}

/// An empty scene's root has two empty children (index 0, no triangles): the CPU traversal must
/// read them as no child. (The slab test "hits" their inverted boxes; before child 0 was skipped,
/// this loop never ended, and the kernel spun until lavapipe's loop budget ran out on every ray.)
#[test]
fn an_empty_scene_is_traversed_at_once() {
    for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
        let empty = build(&rt_core::Scene::default(), layout);
        let hit = rt_core::estimator::trace(
            &empty,
            glam::Vec3::ZERO,
            glam::Vec3::new(0.3, 0.5, -0.8).normalize(),
            f32::MAX,
        );
        assert_eq!(hit.triangle, u32::MAX, "{layout:?}: no triangle to hit");
    }
}

/// `scene` with `change` applied to its first textured material.
fn with_textured_material(
    scene: &GpuScene,
    change: impl FnOnce(&mut rt_core::gpu_types::Material),
) -> GpuScene {
    let mut s = scene.clone();
    change(
        s.materials
            .iter_mut()
            .find(|m| m.textures[0].offset != NO_TEXTURE)
            .unwrap(),
    );
    s
}
