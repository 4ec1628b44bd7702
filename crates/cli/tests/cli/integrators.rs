//! `--integrator bdpt`: renders the built-in scene on the CPU backend (where `--device auto` puts
//! it) to the path tracer's image within noise, writes alpha and passes, and is refused, naming
//! what, with a GPU and with what it does not do.

use super::{rt_cli, temp_dir};

fn render(dir: &std::path::Path, name: &str, extra: &[&str]) -> (i32, String, std::path::PathBuf) {
    let out = dir.join(name);
    let mut args = vec![
        "render",
        "--width",
        "24",
        "--height",
        "24",
        "--max-depth",
        "4",
    ];
    args.extend(["-o", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    let (code, _, stderr) = rt_cli(&args);
    (code, stderr, out)
}

fn mean(path: &std::path::Path) -> f64 {
    let image = image::open(path).unwrap().to_rgb32f();
    let sum: f64 = image.pixels().map(|p| f64::from(p.0[1])).sum();
    sum / f64::from(image.width() * image.height())
}

#[test]
fn bdpt_renders_on_the_cpu_and_matches_path_tracing() {
    let dir = temp_dir("integrators");
    let (code, stderr, bdpt) = render(&dir, "bdpt.exr", &["--integrator", "bdpt", "--spp", "64"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("CPU backend"), "{stderr}");
    let (code, stderr, path) = render(&dir, "path.exr", &["--device", "cpu", "--spp", "256"]);
    assert_eq!(code, 0, "{stderr}");
    let (b, p) = (mean(&bdpt), mean(&path));
    assert!(
        p > 0.01 && (b / p - 1.0).abs() < 0.05,
        "bdpt {b} vs path {p}"
    );
}

#[test]
fn bdpt_is_refused_with_what_it_does_not_do() {
    let dir = temp_dir("integrators-refused");
    for (extra, named) in [
        (&["--device", "gpu"][..], "CPU backend only"),
        (&["--device", "all"][..], "CPU backend only"),
        (
            &["--device", "cpu", "--adaptive", "0.05"][..],
            "adaptive sampling",
        ),
        (&["--device", "cpu", "--clamp", "4"][..], "firefly clamp"),
        (
            &["--device", "cpu", "--projection", "fisheye"][..],
            "projection",
        ),
        (&["--device", "cpu", "--fog-density", "0.1"][..], "media"),
    ] {
        let mut args = vec!["--integrator", "bdpt", "--spp", "1"];
        args.extend_from_slice(extra);
        let (code, stderr, out) = render(&dir, "refused.exr", &args);
        assert_ne!(code, 0, "{extra:?} was not refused");
        assert!(stderr.contains(named), "{extra:?}: {stderr}");
        assert!(!out.exists(), "{extra:?} wrote an image");
    }
}

/// Its alpha and passes come from the camera rays' first hits, as the path tracer's.
#[test]
fn bdpt_writes_alpha_and_passes() {
    let dir = temp_dir("integrators-passes");
    for (extra, name) in [
        (&["--transparent"][..], "alpha.exr"),
        (&["--aov", "depth,normal,albedo"][..], "passes.exr"),
        (&["--transparent"][..], "alpha.png"),
    ] {
        let mut args = vec!["--integrator", "bdpt", "--spp", "2"];
        args.extend_from_slice(extra);
        let (code, stderr, out) = render(&dir, name, &args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        assert!(out.exists(), "{extra:?} wrote no image");
    }
    let (code, stderr, path) = render(
        &dir,
        "path-alpha.png",
        &["--device", "cpu", "--spp", "2", "--transparent"],
    );
    assert_eq!(code, 0, "{stderr}");
    let alpha = |file: &std::path::Path| -> Vec<u8> {
        let image = image::open(file).unwrap().to_rgba8();
        image.pixels().map(|p| p.0[3]).collect()
    };
    assert_eq!(
        alpha(&dir.join("alpha.png")),
        alpha(&path),
        "bdpt's alpha is not the path tracer's (the same camera rays)"
    );
}
