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
    let mut scene = rt_core::io::gltf::load_gltf(&data.join("scene.glb"), None).unwrap();
    assert_eq!(scene.lights.len(), 3, "point, spot and sun come through");
    assert!(scene.environment.is_none());
    scene.settings = settings(WIDTH, HEIGHT, 256, 8);
    let image = render(ctx, &scene);
    let reference = image::open(data.join("reference.exr"))
        .expect("reading the Cycles reference")
        .to_rgb32f();
    assert_eq!(reference.dimensions(), (WIDTH, HEIGHT));
    let reference: Vec<[f32; 3]> = reference.pixels().map(|p| p.0).collect();
    let n = f64::from(WIDTH * HEIGHT);
    for ch in 0..3 {
        let ours: f64 = image.pixels.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        let theirs: f64 = reference.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        eprintln!("channel {ch}: rt {ours:.5}, Cycles {theirs:.5}");
        assert!(
            (ours / theirs - 1.0).abs() <= 0.02,
            "channel {ch}: rt's mean {ours:.5} is not within 2% of Cycles' {theirs:.5}"
        );
    }
    let (mut blocks, mut off) = (0, Vec::new());
    for by in (0..HEIGHT).step_by(32) {
        for bx in (0..WIDTH).step_by(32) {
            let (mut ours, mut theirs) = (0.0f64, 0.0f64);
            for y in by..by + 32 {
                for x in bx..bx + 32 {
                    let i = (y * WIDTH + x) as usize;
                    ours += (0..3).map(|c| f64::from(image.pixels[i][c])).sum::<f64>();
                    theirs += reference[i].iter().map(|&c| f64::from(c)).sum::<f64>();
                }
            }
            blocks += 1;
            let d = (ours - theirs).abs();
            if d > 0.08 * theirs && d > 1e-3 * 32.0 * 32.0 * 3.0 {
                off.push((bx, by, ours / theirs - 1.0));
            }
        }
    }
    assert!(
        off.len() as f64 <= 0.05 * f64::from(blocks),
        "{} of {blocks} blocks differ by more than 8%: {off:?}",
        off.len()
    );
}
