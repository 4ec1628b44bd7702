//! Renders to every format, `info`, bad input, environments and view transforms, glTF binaries.

use super::*;

#[test]
fn renders_the_embedded_cornell_box_to_every_format() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("render");
    for ext in ["png", "jpg", "ppm", "exr"] {
        let out = dir.join(format!("cornell.{ext}"));
        let (code, _, stderr) = rt_cli(&[
            "render",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "24",
            "--spp",
            "2",
            "--adapter",
            "cpu",
        ]);
        assert_eq!(code, 0, "{stderr}");
        for field in [
            "adapter:",
            "triangles:",
            "BVH build:",
            "render time:",
            "samples/s:",
            "paths/s:",
        ] {
            assert!(stderr.contains(field), "summary lacks '{field}': {stderr}");
        }
        let img = image::open(&out).unwrap();
        assert_eq!((img.width(), img.height()), (32, 24));
    }
}

#[test]
fn info_describes_a_scene() {
    let (code, stdout, stderr) = rt_cli(&["info"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("triangles: 32") && stdout.contains("light") && stdout.contains("emissive"),
        "{stdout}"
    );
    assert!(stdout.contains("bounds:"), "{stdout}");
}

#[test]
fn bad_arguments_and_files_exit_2_with_one_line() {
    let dir = temp_dir("bad");
    let bad_obj = dir.join("bad.obj");
    std::fs::write(&bad_obj, "v 0 0 0\nf 1 2 3\n").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", "--camera-from", "1,2"],
            "three comma-separated",
        ),
        (
            vec!["render", "--camera-from", "1,x,3"],
            "not a finite number",
        ),
        (
            vec!["render", "--width", "0", "-o", "x.png"],
            "at least 1x1",
        ),
        (vec!["render", "--width=-5"], "invalid value"),
        (
            vec!["render", "--spp", "0", "-o", "x.png"],
            "samples per pixel",
        ),
        (
            vec!["render", "--width", "100000", "-o", "x.png"],
            "exceeds the limit",
        ),
        (vec!["render", "-o", "x.bmp"], "unknown image type"),
        (
            vec!["render", "/nonexistent/scene.obj", "-o", "x.png"],
            "/nonexistent/scene.obj",
        ),
        (
            vec!["render", bad_obj.to_str().unwrap(), "-o", "x.png"],
            "bad.obj:2:",
        ),
        (
            vec!["render", "scene.xyz", "-o", "x.png"],
            "scene.xyz: unknown scene type '.xyz': rt reads .obj, .gltf, .glb, .ply, .stl, .rtproj",
        ),
        (
            vec!["info", "scene.obj", "--gltf-scene", "0"],
            "--gltf-scene needs a .gltf or .glb scene",
        ),
        (
            vec![
                "render",
                "--camera-from",
                "0,0,0",
                "--camera-to",
                "0,0,0",
                "-o",
                "x.png",
            ],
            "same point",
        ),
        (
            vec!["render", "--camera-up", "0,0,1", "-o", "x.png"],
            "parallel",
        ),
        (vec!["render", "--vfov", "180", "-o", "x.png"], "vfov"),
        (vec!["info", dir.to_str().unwrap()], "directory"),
        (vec!["frobnicate"], "unrecognized subcommand"),
    ];
    for (args, needle) in cases {
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 2, "{args:?} should exit 2: {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: error should mention '{needle}': {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
        if !stderr.contains("Usage") {
            let lines: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.contains("XDG_RUNTIME_DIR") && !l.trim().is_empty())
                .collect();
            assert_eq!(
                lines.len(),
                1,
                "{args:?}: expected a one-line error, got {stderr}"
            );
        }
    }
}

/// `--environment` (the built-in studio, a file, or the sun and sky), its rotation and strength,
/// and `--view`: an environment brightens an open scene, strength 0 removes its light, rotation
/// turns it, the neutral view transform changes 8-bit outputs only; bad environment input is a
/// one-line error with exit code 2.
#[test]
fn environments_and_view_transforms_from_the_command_line() {
    let dir = temp_dir("environment");
    let bunny = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/bunny/bunny-lowres-npm.obj"
    );
    let missing = dir.join("missing.hdr");
    let corrupt = dir.join("corrupt.exr");
    std::fs::write(&corrupt, b"definitely not an EXR").unwrap();
    for (args, says) in [
        (
            vec!["--environment", missing.to_str().unwrap()],
            "missing.hdr",
        ),
        (
            vec!["--environment", corrupt.to_str().unwrap()],
            "corrupt.exr",
        ),
        (vec!["--env-strength", "2"], "need an environment"),
        (
            vec!["--environment", "default", "--env-strength", "-1"],
            "strength",
        ),
        (
            vec!["--environment", "default", "--env-rotation", "nan"],
            "rotation",
        ),
        (vec!["--environment", "sky:95"], "sun elevation"),
        (vec!["--environment", "sky:30,x"], "turbidity"),
    ] {
        let mut all = vec!["render", bunny, "--spp", "1", "-o"];
        let out = dir.join("bad.png");
        all.push(out.to_str().unwrap());
        all.extend(args.iter().copied());
        let (code, _, stderr) = rt_cli(&all);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(
            stderr.trim().lines().count(),
            1,
            "{args:?}: one line: {stderr}"
        );
        assert!(!out.exists());
    }
    if !has_gpu() {
        return;
    }
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render", bunny, "--width", "32", "--height", "32", "--spp", "8",
        ];
        args.push("-o");
        args.push(out.to_str().unwrap());
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        image::open(&out).unwrap().to_rgb32f()
    };
    let mean = |img: &image::Rgb32FImage| {
        img.pixels()
            .map(|p| f64::from(p.0[0] + p.0[1] + p.0[2]))
            .sum::<f64>()
            / img.len() as f64
    };
    let ambient = render("ambient.exr", &["--ambient", "0,0,0"]);
    let studio = render(
        "studio.exr",
        &["--ambient", "0,0,0", "--environment", "default"],
    );
    let dark = render(
        "dark.exr",
        &[
            "--ambient",
            "0,0,0",
            "--environment",
            "default",
            "--env-strength",
            "0",
        ],
    );
    let turned = render(
        "turned.exr",
        &["--environment", "default", "--env-rotation", "90"],
    );
    assert_eq!(
        mean(&ambient),
        0.0,
        "no light without ambient or environment"
    );
    assert!(mean(&studio) > 0.01, "the studio lights the bunny");
    assert_eq!(mean(&dark), 0.0, "strength 0 turns it off");
    assert_ne!(studio.as_raw(), turned.as_raw(), "rotation turns the light");
    let standard = render(
        "standard.png",
        &["--environment", "default", "--exposure", "4"],
    );
    let neutral = render(
        "neutral.png",
        &[
            "--environment",
            "default",
            "--exposure",
            "4",
            "--view",
            "neutral",
        ],
    );
    assert_ne!(
        standard.as_raw(),
        neutral.as_raw(),
        "the view transform changes PNGs"
    );
    // The sun and sky lights the bunny, and turning it moves the sun (the physics of the sky is
    // tested in crates/core/src/sky.rs and tests/analytic/).
    let sky = render("sky.exr", &["--environment", "sky:30,4"]);
    let turned_sky = render(
        "sky-turned.exr",
        &["--environment", "sky:30,4", "--env-rotation", "120"],
    );
    assert!(
        mean(&sky) > 0.01 && mean(&sky).is_finite(),
        "{}",
        mean(&sky)
    );
    assert_ne!(sky.as_raw(), turned_sky.as_raw(), "rotation turns the sun");
    let exr_a = render("a.exr", &["--environment", "default", "--view", "neutral"]);
    let exr_b = render("b.exr", &["--environment", "default"]);
    assert_eq!(exr_a.as_raw(), exr_b.as_raw(), "EXR stays linear");
    std::fs::remove_dir_all(&dir).ok();
}

/// A real .glb (Khronos' Box Textured) renders, and `info` describes it; a scene index it lacks is
/// a one-line error.
#[test]
fn renders_and_describes_a_gltf_binary() {
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/BoxTextured.glb");
    let (code, stdout, stderr) = rt_cli(&["info", glb]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("triangles: 12"), "{stdout}");
    assert!(stdout.contains("pbr"), "{stdout}");
    let dir = temp_dir("gltf");
    let out = dir.join("box.png");
    let (code, _, stderr) = rt_cli(&[
        "render",
        glb,
        "--gltf-scene",
        "5",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("no scene 5"), "{stderr}");
    if !has_gpu() {
        return;
    }
    let out = dir.join("box.exr");
    let args = [
        "render", glb, "--width", "24", "--height", "24", "--spp", "4", "-o",
    ];
    let (code, _, stderr) = rt_cli(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{stderr}");
    let image = image::open(&out).unwrap().to_rgb32f();
    let lit = image
        .pixels()
        .filter(|p| p.0.iter().any(|c| *c > 0.05))
        .count();
    assert!(
        lit > 24 * 24 / 4,
        "the box is lit and in view: {lit} pixels"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Fog from the command line: bad values are one-line errors naming the flag (exit code 2, no
/// output written); `info` reports the fog; on the CPU backend a light haze dims the Cornell box's
/// walls seen through it and glows where the lamp lights it (the image changes, nothing is NaN).
#[test]
fn fog_from_the_command_line() {
    let dir = temp_dir("fog");
    for (args, says) in [
        (vec!["--fog-density", "-1"], "fog density"),
        (vec!["--fog-density", "nan"], "fog density"),
        (
            vec!["--fog-density", "0.1", "--fog-albedo", "1.5,0,0"],
            "fog albedo",
        ),
        (
            vec!["--fog-density", "0.1", "--fog-anisotropy", "1"],
            "fog anisotropy",
        ),
    ] {
        let out = dir.join("bad.png");
        let mut all = vec!["render", "--spp", "1", "-o", out.to_str().unwrap()];
        all.extend(args.iter().copied());
        let (code, _, stderr) = rt_cli(&all);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
        assert!(!out.exists());
    }
    let (code, stdout, stderr) = rt_cli(&["info", "--fog-density", "0.002"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("fog: density 0.002 (mean free path 500.0"),
        "{stdout}"
    );
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render",
            "--device",
            "cpu",
            "--width",
            "24",
            "--height",
            "24",
            "--spp",
            "16",
            "--max-depth",
            "6",
            "-o",
        ];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        let image = image::open(&out).unwrap().to_rgb32f();
        image.pixels().map(|p| p.0).collect::<Vec<_>>()
    };
    let clear = render("clear.exr", &[]);
    let foggy = render(
        "fog.exr",
        &["--fog-density", "0.002", "--fog-anisotropy", "0.5"],
    );
    assert!(foggy.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
    let changed = clear.iter().zip(&foggy).filter(|(a, b)| a != b).count();
    assert!(changed * 2 > clear.len(), "fog changed {changed} pixels");
}

/// `mesh` as an ASCII STL (facet normals left zero, as some exporters write them).
fn ascii_stl(mesh: &rt_core::Mesh) -> String {
    let mut stl = String::from("solid ball\n");
    for t in &mesh.indices {
        stl += "facet normal 0 0 0\nouter loop\n";
        for &i in t {
            let p = mesh.positions[i as usize];
            stl += &format!("vertex {} {} {}\n", p.x, p.y, p.z);
        }
        stl += "endloop\nendfacet\n";
    }
    stl + "endsolid ball\n"
}

/// An STL renders on the CPU backend, flat by default and smoothly with `--smooth-normals` (another
/// image, and another again at a 5° crease, which keeps this ball's facets); a value needs `=`,
/// so the scene path after the flag stays the scene.
#[test]
fn an_stl_renders_flat_or_smooth() {
    let dir = temp_dir("stl");
    let scene = dir.join("ball.stl");
    std::fs::write(&scene, ascii_stl(&rt_core::shapes::uv_sphere(1.0, 6, 12))).unwrap();
    let render = |extra: &[&str], name: &str| {
        let out = dir.join(name);
        let mut args = vec![
            "render", "--device", "cpu", "--width", "24", "--height", "24",
        ];
        args.extend(["--spp", "4", "-o", out.to_str().unwrap()]);
        args.extend(extra);
        args.push(scene.to_str().unwrap());
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{stderr}");
        std::fs::read(out).unwrap()
    };
    let flat = render(&[], "flat.exr");
    let smooth = render(&["--smooth-normals"], "smooth.exr");
    let sharper = render(&["--smooth-normals=5"], "five.exr");
    assert_ne!(flat, smooth, "smoothing changes the shading");
    assert_ne!(smooth, sharper, "the crease angle matters");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--projection` and a camera file's "projection" reach the render: an orthographic view of the
/// Cornell box differs from the perspective one, a fisheye's corners are black, a panorama renders;
/// an unknown projection or a bad height is an error naming the flag's values.
#[test]
fn projections_from_flags_and_camera_files_render() {
    let dir = temp_dir("projections");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render", "--device", "cpu", "--width", "32", "--height", "24",
        ];
        args.extend(["--spp", "4", "-o", out.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        image::open(&out).unwrap().to_rgb32f()
    };
    let perspective = render("p.exr", &[]);
    let ortho = render("o.exr", &["--projection", "orthographic"]);
    assert_ne!(perspective, ortho);
    let fisheye = render(
        "f.exr",
        &["--projection", "fisheye", "--fisheye-angle", "160"],
    );
    assert_eq!(
        fisheye.get_pixel(0, 0).0,
        [0.0; 3],
        "outside the image circle"
    );
    assert!(fisheye.get_pixel(16, 12).0[0] > 0.0, "inside it");
    let camera = dir.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"from": [278, 273, -800], "to": [278, 273, 0], "projection": "panorama"}"#,
    )
    .unwrap();
    let panorama = render("pano.exr", &["--camera", camera.to_str().unwrap()]);
    assert_ne!(panorama, perspective);
    let (code, _, stderr) = rt_cli(&["render", "--projection", "cylinder"]);
    assert_ne!(code, 0);
    assert!(stderr.contains("orthographic"), "{stderr}");
    let out = dir.join("bad.exr");
    let (code, _, stderr) = rt_cli(&[
        "render",
        "--device",
        "cpu",
        "--projection",
        "orthographic",
        "--ortho-height",
        "0",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("orthographic height"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--view agx` and `--white-balance` change the PNG (not the EXR's linear values); 3200 K cools
/// the Cornell box's PNG (blue up, red down); a temperature outside 1667–25000 K is refused.
#[test]
fn agx_and_white_balance_shape_8_bit_outputs() {
    let dir = temp_dir("views");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render", "--device", "cpu", "--width", "16", "--height", "16",
        ];
        args.extend(["--spp", "4", "-o", out.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        image::open(&out).unwrap().to_rgb8()
    };
    let mean = |img: &image::RgbImage, c: usize| {
        img.pixels().map(|p| f64::from(p.0[c])).sum::<f64>() / img.len() as f64
    };
    let standard = render("s.png", &[]);
    let agx = render("a.png", &["--view", "agx"]);
    assert_ne!(standard, agx);
    let cool = render("w.png", &["--white-balance", "3200"]);
    assert!(mean(&cool, 2) > mean(&standard, 2) && mean(&cool, 0) < mean(&standard, 0));
    let (code, _, stderr) = rt_cli(&["render", "--white-balance", "900"]);
    assert_ne!(code, 0);
    assert!(stderr.contains("1667"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--region` renders only a window, and its pixels are the whole render's there, bit for bit (they
/// take the same samples), on the CPU backend and on the GPU; `--into` pastes the window into the
/// whole image, so re-rendering a region of a finished image gives that image back.
#[test]
fn a_region_is_the_same_window_of_the_whole_render() {
    let dir = temp_dir("region");
    let mut devices = vec!["cpu"];
    if has_gpu() {
        devices.push("gpu");
    }
    for device in devices {
        let render = |name: &str, extra: &[&str]| {
            let out = dir.join(name);
            let mut args = vec![
                "render", "--device", device, "--width", "32", "--height", "24",
            ];
            args.extend(["--spp", "3", "-o", out.to_str().unwrap()]);
            args.extend_from_slice(extra);
            let (code, _, stderr) = rt_cli(&args);
            assert_eq!(code, 0, "{device} {extra:?}: {stderr}");
            out
        };
        let whole = image::open(render("whole.exr", &[])).unwrap().to_rgb32f();
        let window = image::open(render("window.exr", &["--region", "8,4,24,20"]))
            .unwrap()
            .to_rgb32f();
        assert_eq!((window.width(), window.height()), (16, 16));
        for (x, y, p) in window.enumerate_pixels() {
            assert_eq!(
                p,
                whole.get_pixel(x + 8, y + 4),
                "{device}: pixel ({x}, {y})"
            );
        }
        let whole_path = dir.join("whole.exr");
        let pasted = render(
            "pasted.exr",
            &[
                "--region",
                "8,4,24,20",
                "--into",
                whole_path.to_str().unwrap(),
            ],
        );
        let pasted = image::open(pasted).unwrap().to_rgb32f();
        assert_eq!(
            pasted, whole,
            "{device}: the window pasted back changes nothing"
        );
    }
    let (code, _, stderr) = rt_cli(&[
        "render", "--width", "16", "--height", "16", "--region", "0,0,17,4",
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("reaches past"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--transparent` writes alpha (PNG: 0 where the camera sees the background, 255 on the box);
/// `--aov` writes named layers into the EXR beside the beauty and its premultiplied alpha; both
/// refuse outputs that cannot hold them.
#[test]
fn transparent_backgrounds_and_render_passes_are_written() {
    let dir = temp_dir("layers");
    let camera = super::outside_camera(&dir);
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render", "--device", "cpu", "--width", "24", "--height", "24",
        ];
        args.extend([
            "--spp",
            "4",
            "--camera",
            camera.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        out
    };
    let png = image::open(render("t.png", &["--transparent", "--ambient", "1,1,1"])).unwrap();
    let png = png.as_rgba8().expect("an RGBA PNG");
    assert_eq!(png.get_pixel(0, 0).0[3], 0, "background");
    assert_eq!(png.get_pixel(12, 12).0[3], 255, "the box");
    let exr = render(
        "passes.exr",
        &["--transparent", "--aov", "depth,normal,object,material"],
    );
    let layers = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
    let channels = &layers.layer_data[0].channel_data.list;
    let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
    for name in [
        "A",
        "B",
        "G",
        "R",
        "depth.Z",
        "normal.X",
        "normal.Y",
        "normal.Z",
        "object.ID",
        "material.ID",
    ] {
        assert!(
            names.iter().any(|n| n == name),
            "{name} missing from {names:?}"
        );
    }
    let values = |name: &str| -> Vec<f32> {
        let c = channels
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap();
        c.sample_data.values_as_f32().collect()
    };
    let (depth, alpha, object) = (values("depth.Z"), values("A"), values("object.ID"));
    let centre = 12 * 24 + 12;
    assert_eq!(alpha[0], 0.0);
    assert_eq!(depth[0], 1e10, "nothing met: Blender's background depth");
    assert!(
        depth[centre] > 1600.0 && depth[centre] < 2300.0,
        "depth {}",
        depth[centre]
    );
    assert!(object[centre] >= 1.0 && object[0] == 0.0);
    for (extra, message) in [
        (&["--aov", "depth"][..], "name the output .exr"),
        (&["--transparent"][..], "with alpha"),
    ] {
        let out = dir.join("x.jpg");
        let mut args = vec!["render", "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_ne!(code, 0);
        assert!(stderr.contains(message), "{stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `rt-cli preview` leaves the editor's floor grid out of the image unless `--grid` asks for it.
#[test]
fn the_preview_image_has_no_grid_unless_asked() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("preview-grid");
    let scene = dir.join("ball.stl");
    std::fs::write(&scene, ascii_stl(&rt_core::shapes::uv_sphere(1.0, 8, 16))).unwrap();
    let preview = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "preview",
            "--width",
            "64",
            "--height",
            "48",
            "--camera-from",
            "0,2,6",
        ];
        args.extend(["-o", out.to_str().unwrap(), scene.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{stderr}");
        image::open(out).unwrap().to_rgb8()
    };
    assert_ne!(preview("plain.png", &[]), preview("grid.png", &["--grid"]));
    std::fs::remove_dir_all(&dir).unwrap();
}
