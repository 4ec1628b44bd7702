#![allow(clippy::unwrap_used)]
//! The compressed wide BVH (CWBVH) finds the same nearest hit as the BVH2 for every ray: the two
//! CPU traversals (which mirror `cwbvh.wgsl` and `bvh.wgsl`) over the shipped scenes, a random
//! triangle soup, one triangle and an empty scene, with rays from inside and outside each scene.

use std::sync::Arc;

use glam::Vec3;
use rt_core::bvh::{BvhLayout, BvhQuality, MAX_WIDE_BVH_DEPTH};
use rt_core::math::rng::Rng;
use rt_core::scene::{Mesh, Object};
use rt_core::{GpuScene, Material, Scene};
use rt_io::obj::load_obj;

fn scene_of(positions: Vec<Vec3>) -> Scene {
    let indices = (0..positions.len() as u32 / 3)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    Scene {
        objects: vec![Object {
            shadow_catcher: false,
            animation_node: None,
            name: "soup".into(),
            mesh: Arc::new(Mesh {
                positions,
                normals: None,
                uvs: None,
                colors: None,
                indices,
            }),
            material: Material::Lambertian {
                albedo: [0.5; 3],
                texture: None,
            },
            transform: Default::default(),
        }],
        ..Default::default()
    }
}

fn scenes() -> Vec<(&'static str, Scene)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let mut rng = Rng::new(7, 0, 1);
    let mut r = move || rng.next_f32();
    let soup = (0..3000)
        .flat_map(|_| {
            let c = Vec3::new(r(), r(), r()) * 10.0;
            let size = 0.02 + r() * r();
            [(); 3].map(|_| c + (Vec3::new(r(), r(), r()) - 0.5) * size)
        })
        .collect();
    vec![
        ("cornell", rt_io::assets::cornell_box().unwrap()),
        (
            "bunny",
            load_obj(&root.join("bunny/bunny-lowres-npm.obj"), 0).unwrap(),
        ),
        (
            "spot",
            load_obj(&root.join("spot/spot_triangulated_textured.obj"), 0).unwrap(),
        ),
        ("soup", scene_of(soup)),
        ("a soup built in runs", soup_in_runs()),
        ("fan over repeated corners", repeated_corner_fan()),
        ("one triangle", scene_of(vec![Vec3::ZERO, Vec3::X, Vec3::Y])),
        ("empty", Scene::default()),
    ]
}

/// 140,000 small triangles through a box, ten of them copies of one triangle: more than two
/// of the builder's runs (`bvh::chunked`, 65,536 triangles), so both layouts build it run by run.
fn soup_in_runs() -> Scene {
    let mut rng = Rng::new(5, 0, 3);
    let mut r = move || rng.next_f32();
    let copy = [
        Vec3::splat(5.0),
        Vec3::new(5.1, 5.0, 5.0),
        Vec3::new(5.0, 5.1, 5.0),
    ];
    let positions = (0..140_000)
        .flat_map(|i| {
            if i % 14_000 == 0 {
                return copy;
            }
            let c = Vec3::new(r(), r(), r()) * 10.0;
            [(); 3].map(|_| c + (Vec3::new(r(), r(), r()) - 0.5) * 0.05)
        })
        .collect();
    scene_of(positions)
}

/// What `box_longline.obj` (Debian's assimp-testmodels) makes: one face of 470 vertices that
/// repeats a quad's four corners, fan-triangulated into hundreds of coincident and degenerate
/// triangles, plus 2,000 copies of one triangle beside it.
fn repeated_corner_fan() -> Scene {
    let corners = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let polygon: Vec<Vec3> = (0..470).map(|i| corners[i % 4]).collect();
    let mut positions: Vec<Vec3> = polygon
        .windows(2)
        .skip(1)
        .flat_map(|pair| [polygon[0], pair[0], pair[1]])
        .collect();
    let copy = [
        Vec3::new(2.0, 0.0, 0.5),
        Vec3::new(3.0, 0.0, 0.5),
        Vec3::new(2.0, 1.0, 0.5),
    ];
    positions.extend((0..2000).flat_map(|_| copy));
    scene_of(positions)
}

/// Coincident and degenerate triangles chain the surface-area builder's tree hundreds of levels
/// deep; both layouts then take the median-split tree, within their traversal stacks, and stay
/// the layout asked for.
#[test]
fn coincident_triangles_build_within_the_traversal_stacks() {
    let scene = repeated_corner_fan();
    for (layout, bound) in [
        (BvhLayout::Bvh2, rt_core::bvh::MAX_BVH_DEPTH),
        (BvhLayout::Cwbvh, MAX_WIDE_BVH_DEPTH),
    ] {
        let built = GpuScene::build_with_layout(&scene, BvhQuality::Medium, layout).unwrap();
        assert_eq!(built.layout, layout);
        assert!(
            built.bvh_depth <= bound,
            "{layout:?}: depth {}",
            built.bvh_depth
        );
        built.check_kernel_indices().unwrap();
        let hit = rt_core::estimator::trace(&built, Vec3::new(0.3, 0.6, 1.0), -Vec3::Z, f32::MAX);
        assert!((hit.t - 1.0).abs() < 1e-6, "{layout:?}: {hit:?}");
        let hit = rt_core::estimator::trace(&built, Vec3::new(2.2, 0.2, 1.0), -Vec3::Z, f32::MAX);
        assert!((hit.t - 0.5).abs() < 1e-6, "{layout:?}: {hit:?}");
    }
}

#[test]
fn wide_and_binary_bvhs_find_the_same_nearest_hits() {
    for (name, scene) in scenes() {
        let bvh2 =
            GpuScene::build_with_layout(&scene, BvhQuality::Medium, BvhLayout::Bvh2).unwrap();
        let wide =
            GpuScene::build_with_layout(&scene, BvhQuality::Medium, BvhLayout::Cwbvh).unwrap();
        assert_eq!(bvh2.triangles.len(), wide.triangles.len(), "{name}");
        assert!(wide.bvh_depth <= MAX_WIDE_BVH_DEPTH, "{name}");
        let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let size = (hi - lo).max(Vec3::splat(1e-3));
        let mut rng = Rng::new(3, 0, 11);
        let mut r = move || rng.next_f32();
        let (mut rays, mut hits) = (0, 0);
        for i in 0..20_000 {
            // Half from outside the bounds towards a point inside, half from inside in any direction;
            // every 50th along an axis (zero direction components).
            let inside = lo + size * Vec3::new(r(), r(), r());
            let (origin, mut direction) = if i % 2 == 0 {
                let outside = (lo + hi) / 2.0 + size * 2.0 * (Vec3::new(r(), r(), r()) - 0.5);
                (outside, inside - outside)
            } else {
                (inside, Vec3::new(r(), r(), r()) - 0.5)
            };
            if i % 50 == 0 {
                let axis = (i / 50) % 3;
                direction = Vec3::ZERO;
                direction[axis] = if i % 100 == 0 { 1.0 } else { -1.0 };
            }
            let direction = direction.normalize_or(Vec3::Z);
            let a = rt_core::estimator::trace(&bvh2, origin, direction, f32::MAX);
            let b = rt_core::estimator::trace(&wide, origin, direction, f32::MAX);
            rays += 1;
            assert_eq!(
                a.triangle == u32::MAX,
                b.triangle == u32::MAX,
                "{name}: ray {i} from {origin} along {direction}: BVH2 {a:?}, wide {b:?}"
            );
            if a.triangle != u32::MAX {
                hits += 1;
                // Both test the same triangles with the same watertight test; only which of two
                // triangles meeting at the hit point is reported may differ.
                assert!(
                    (a.t - b.t).abs() <= 1e-5 * a.t,
                    "{name}: ray {i}: BVH2 t {} wide t {}",
                    a.t,
                    b.t
                );
                if a.triangle != b.triangle {
                    let (ta, tb) = (
                        bvh2.triangles[a.triangle as usize],
                        wide.triangles[b.triangle as usize],
                    );
                    let shares_a_vertex = [ta.v0, ta.v1, ta.v2]
                        .iter()
                        .any(|v| [tb.v0, tb.v1, tb.v2].contains(v));
                    assert!(
                        shares_a_vertex,
                        "{name}: ray {i}: different triangles {ta:?} {tb:?}"
                    );
                }
            }
        }
        if name != "empty" {
            assert!(hits > rays / 10, "{name}: only {hits} of {rays} rays hit");
        }
    }
}

/// Coordinates near f32's range overflow obvhs' wide-collapse costs (the project fuzzer found its
/// debug assertion firing on a Cornell box with one vertex at -1.7e38): such a scene falls back to
/// the BVH2 and still traces.
#[test]
fn huge_coordinates_fall_back_to_the_binary_bvh() {
    let mut positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    positions.extend([Vec3::new(0.0, 0.0, -1.701_411_8e38), Vec3::X, Vec3::Y]);
    let scene = scene_of(positions);
    let built = GpuScene::build_with_layout(&scene, BvhQuality::Medium, BvhLayout::Cwbvh).unwrap();
    assert_eq!(built.layout, BvhLayout::Bvh2);
    built.check_kernel_indices().unwrap();
    let hit = rt_core::estimator::trace(&built, Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, f32::MAX);
    assert!((hit.t - 1.0).abs() < 1e-6, "{hit:?}");
    let ordinary = scene_of(vec![Vec3::ZERO, Vec3::X * 1e14, Vec3::Y * 1e14]);
    let built =
        GpuScene::build_with_layout(&ordinary, BvhQuality::Medium, BvhLayout::Cwbvh).unwrap();
    assert_eq!(built.layout, BvhLayout::Cwbvh);
}
