//! `--frames` and `--turntable`: animations rendered frame by frame.

use super::*;

/// `--frames 1..2` renders a glTF animation frame by frame to OUT.0001.EXT, OUT.0002.EXT: an
/// emissive card keyed from x = −1 (frame 1, time 0) to x = +1 (frame 2, time 1 at --fps 1) is
/// seen left of centre, then right of it; a project saved from the file renders the same frames.
/// `--turntable 2` turns the camera half way round.
#[test]
fn frames_render_an_animation_and_a_turntable() {
    let dir = temp_dir("frames");
    let mut bin = Vec::new();
    let floats = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    floats(
        &mut bin,
        &[-0.5, -0.5, 0., 0.5, -0.5, 0., 0.5, 0.5, 0., -0.5, 0.5, 0.],
    );
    [0u16, 1, 2, 0, 2, 3]
        .iter()
        .for_each(|i| bin.extend(i.to_le_bytes()));
    floats(&mut bin, &[0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    std::fs::write(dir.join("card.bin"), &bin).unwrap();
    let gltf = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
      "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 4]}],
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
      "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
                     "emissiveFactor": [1, 1, 1]}],
      "animations": [{"samplers": [{"input": 2, "output": 3}],
                      "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
        {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 12},
        {"buffer": 0, "byteOffset": 60, "byteLength": 8},
        {"buffer": 0, "byteOffset": 68, "byteLength": 24}],
      "buffers": [{"byteLength": 92, "uri": "card.bin"}]}"#;
    let scene = dir.join("card.gltf");
    std::fs::write(&scene, gltf).unwrap();
    // Frames 1 and 2 of `input` at 1 frame a second, to OUT.0001.png and OUT.0002.png.
    let render_frames = |input: &std::path::Path, out: &std::path::Path| {
        let (code, _, stderr) = rt_cli(&[
            "render",
            "--device",
            "cpu",
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "2",
            "--frames",
            "1..2",
            "--fps",
            "1",
            "-o",
            out.to_str().unwrap(),
            input.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
    };
    let out = dir.join("shot.png");
    render_frames(&scene, &out);
    assert!(!out.exists(), "frames are numbered");
    // The mean column of the lit pixels.
    let centroid = |name: &str| {
        let img = image::open(dir.join(name)).unwrap().to_luma8();
        let lit: Vec<u32> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0[0] > 128)
            .map(|(x, _, _)| x)
            .collect();
        assert!(!lit.is_empty(), "{name}: the card is not in view");
        lit.iter().sum::<u32>() as f32 / lit.len() as f32
    };
    let (first, second) = (centroid("shot.0001.png"), centroid("shot.0002.png"));
    assert!(
        first < 14.0 && second > 18.0,
        "card at columns {first}, then {second}"
    );
    // A project saved from the file keeps the animation: its frames are the file's, bit for bit.
    let project = dir.join("card.rtproj");
    let loaded = rt_io::load(&scene, &Default::default()).unwrap();
    rt_io::project::save_project(&loaded, &project).unwrap();
    render_frames(&project, &dir.join("project.png"));
    for frame in ["0001", "0002"] {
        let read = |name: &str| std::fs::read(dir.join(format!("{name}.{frame}.png"))).unwrap();
        assert!(read("shot") == read("project"), "frame {frame}");
    }
    let (code, stdout, stderr) = rt_cli(&["info", project.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("animation: 1 channel moving 1 node, 0 to 1.000 s"),
        "{stdout}"
    );
    let turn = dir.join("turn.exr");
    let (code, _, stderr) = rt_cli(&[
        "render",
        "--device",
        "cpu",
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "2",
        "--turntable",
        "2",
        "-o",
        turn.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let a = std::fs::read(dir.join("turn.0001.exr")).unwrap();
    let b = std::fs::read(dir.join("turn.0002.exr")).unwrap();
    assert_ne!(a, b, "the second frame looks from the other side");
    std::fs::remove_dir_all(&dir).unwrap();
}
