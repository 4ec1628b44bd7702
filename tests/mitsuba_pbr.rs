//! rt's PBR materials and environment lighting against Mitsuba 3: the scene, environment and
//! 8192-spp reference in `tests/data/mitsuba-pbr/` come from `bench/mitsuba-pbr.py`, whose header
//! lists the Mitsuba plugins and parameters matched to each rt material. rt's image must have
//! every channel's mean within 1% of Mitsuba's and 95% of its 32-pixel blocks within 5%.

mod common;

use std::path::Path;

use common::*;
use rt_core::Environment;
use rt_core::environment::load_environment;

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;

#[test]
fn pbr_materials_and_an_environment_match_mitsuba() {
    let Some(ctx) = gpu() else { return };
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mitsuba-pbr");
    let mut scene = rt_core::io::obj::load_obj(&data.join("scene.obj"), 0).unwrap();
    scene.camera.from = [0.0, 1.6, 5.2];
    scene.camera.to = [0.0, 0.55, 0.0];
    scene.camera.up = [0.0, 1.0, 0.0];
    scene.camera.vfov_deg = 32.0;
    scene.settings = settings(WIDTH, HEIGHT, 256, 8);
    let env = data.join("env.exr");
    scene.environment = Some(Environment::new(
        env.display().to_string(),
        load_environment(&env).unwrap(),
    ));
    let image = render(ctx, &scene);
    let reference = image::open(data.join("reference.exr"))
        .expect("reading the Mitsuba reference")
        .to_rgb32f();
    assert_eq!(reference.dimensions(), (WIDTH, HEIGHT));
    let reference: Vec<[f32; 3]> = reference.pixels().map(|p| p.0).collect();

    let n = f64::from(WIDTH * HEIGHT);
    for ch in 0..3 {
        let ours: f64 = image.pixels.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        let theirs: f64 = reference.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        eprintln!("channel {ch}: rt {ours:.5}, Mitsuba {theirs:.5}");
        assert!(
            (ours / theirs - 1.0).abs() <= 0.01,
            "channel {ch}: rt's mean {ours:.5} is not within 1% of Mitsuba's {theirs:.5}"
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
            let d = ours / theirs - 1.0;
            if d.abs() > 0.05 {
                off.push((bx, by, d));
            }
        }
    }
    assert!(
        off.len() as f64 <= 0.05 * f64::from(blocks),
        "{} of {blocks} blocks differ by more than 5%: {off:?}",
        off.len()
    );
}
