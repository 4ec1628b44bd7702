//! `--region` with `--transparent` and `--into`: the window's colour and alpha pasted back into a
//! transparent render of the whole image give that image back (EXR and PNG); `--aov` is refused
//! there with the way out. A project saved transparent writes alpha without the flag.

use super::{rt_cli, temp_dir};

#[test]
fn a_transparent_region_pastes_back_with_its_alpha() {
    let dir = temp_dir("transparent-region");
    // The window below straddles the box's edge: it holds background (alpha 0), box (1) and edge
    // pixels.
    let camera = super::outside_camera(&dir);
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render", "--device", "cpu", "--width", "32", "--height", "24",
        ];
        args.extend(["--spp", "3", "--transparent", "--ambient", "1,1,1"]);
        args.extend([
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
    for ext in ["exr", "png"] {
        let whole = render(&format!("whole.{ext}"), &[]);
        let pasted = render(
            &format!("pasted.{ext}"),
            &["--region", "0,4,20,20", "--into", whole.to_str().unwrap()],
        );
        let whole = image::open(&whole).unwrap().to_rgba32f();
        let pasted = image::open(&pasted).unwrap().to_rgba32f();
        let alphas: Vec<f32> = (4..20)
            .flat_map(|y| (0..20).map(move |x| (x, y)))
            .map(|(x, y)| whole.get_pixel(x, y).0[3])
            .collect();
        assert!(
            alphas.contains(&0.0) && alphas.contains(&1.0),
            "{ext}: the window holds background and box: {alphas:?}"
        );
        assert!(
            pasted == whole,
            "{ext}: the window pasted back with its alpha changes nothing"
        );
    }
    let whole = dir.join("whole.exr");
    let out = dir.join("x.exr");
    let (code, _, stderr) = rt_cli(&[
        "render",
        "--region",
        "0,0,8,8",
        "--into",
        whole.to_str().unwrap(),
        "--aov",
        "depth",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("leave out --aov"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A project saved transparent renders with alpha without `--transparent`: the scene's setting
/// alone keeps the first hits the alpha is made of (it once wrote an opaque PNG with a black
/// background).
#[test]
fn a_project_saved_transparent_writes_alpha() {
    let dir = temp_dir("transparent-project");
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 24;
    scene.settings.samples_per_pixel = 2;
    scene.settings.transparent = true;
    // Outside the box, looking at it (as `outside_camera`).
    scene.camera.from = [278.0, 273.0, -1600.0];
    scene.camera.to = [278.0, 273.0, 0.0];
    scene.camera.vfov_deg = 40.0;
    let project = dir.join("t.rtproj");
    rt_io::project::save_project(&scene, &project).unwrap();
    let out = dir.join("t.png");
    let (code, _, stderr) = rt_cli(&[
        "render",
        project.to_str().unwrap(),
        "--device",
        "cpu",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let png = image::open(&out).unwrap();
    let png = png.as_rgba8().expect("an RGBA PNG");
    assert_eq!(png.get_pixel(0, 0).0[3], 0, "background");
    assert_eq!(png.get_pixel(12, 12).0[3], 255, "the box");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--shadow-catcher floor` on the built-in Cornell box: the floor turns transparent where the
/// lamp reaches it and keeps the blocks' shadows (a film made transparent for it), the rest of
/// the image keeps its alpha; bidirectional path tracing refuses it, and a name the scene lacks
/// is an error listing the names it has.
#[test]
fn a_shadow_catcher_floor_keeps_only_its_shadows() {
    let dir = temp_dir("shadow-catcher");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["render", "--width", "48", "--height", "48", "--spp", "64"];
        args.extend(["--max-depth", "4", "-o", out.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let (code, _, stderr) = rt_cli(&args);
        (code, stderr, out)
    };
    let alpha = |file: &std::path::Path| -> Vec<f32> {
        let image = image::open(file).unwrap().to_rgba32f();
        image.pixels().map(|p| p.0[3]).collect()
    };
    let (code, stderr, plain) = render("plain.png", &["--device", "cpu", "--transparent"]);
    assert_eq!(code, 0, "{stderr}");
    let (code, stderr, caught) = render(
        "caught.png",
        &["--device", "cpu", "--shadow-catcher", "floor"],
    );
    assert_eq!(code, 0, "{stderr}");
    let (plain, caught) = (alpha(&plain), alpha(&caught));
    let floor: Vec<f32> = plain
        .iter()
        .zip(&caught)
        .filter(|(p, c)| **c < **p - 0.01)
        .map(|(_, c)| *c)
        .collect();
    assert!(floor.len() > 48 * 48 / 20, "{} floor pixels", floor.len());
    assert!(
        plain.iter().zip(&caught).all(|(p, c)| c <= p),
        "a catcher adds alpha"
    );
    let lit = floor.iter().filter(|a| **a < 0.15).count();
    let shadowed = floor.iter().filter(|a| **a > 0.5).count();
    assert!(lit > 10 && shadowed > 3, "lit {lit}, shadowed {shadowed}");
    let (code, stderr, out) = render(
        "bdpt.png",
        &["--integrator", "bdpt", "--shadow-catcher", "floor"],
    );
    assert!(code != 0 && stderr.contains("shadow catchers"), "{stderr}");
    assert!(!out.exists());
    let (code, stderr, _) = render("none.png", &["--shadow-catcher", "flor"]);
    assert!(code != 0 && stderr.contains("floor, ceiling"), "{stderr}");
}
