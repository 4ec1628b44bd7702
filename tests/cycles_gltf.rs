//! glTF import against Blender Cycles: `bench/cycles-vs-rt.py` built the scene in Blender (Principled
//! metals and plastic, a point, a spot and a sun light, a camera), exported `scene.glb` and rendered
//! Cycles' 1024-spp `reference.exr` (the script's header says what was matched and why). rt renders
//! the .glb as a user would open it; every channel's mean must be within 2% of Cycles' and 95% of
//! the 32-px blocks within 8% (blocks of black sky agree when both are dark).

mod common;

use std::path::Path;

use common::*;

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;

#[test]
fn a_gltf_exported_by_blender_renders_as_cycles_renders_it() {
    let Some(ctx) = gpu() else { return };
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cycles-gltf");
    let mut scene = rt_io::gltf::load_gltf(&data.join("scene.glb"), None).unwrap();
    assert_eq!(scene.lights.len(), 3, "point, spot and sun come through");
    assert!(scene.environment.is_none());
    scene.settings = settings(WIDTH, HEIGHT, 256, 8);
    let image = render(ctx, &scene);
    assert_matches_reference(&image, &data.join("reference.exr"), "Cycles", 0.02, 0.08);
}
