//! `render --device cpu`, the native CPU backend: the GPU's image from the same samples, parts that
//! merge with GPU parts, and a clear refusal of what it does not do yet.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

mod common;
use std::path::{Path, PathBuf};

use common::{agreeing_pixels, has_gpu, merge_parts, render_cornell, rt_cli, temp_dir};
use rt_core::part::{Part, read_part};

const W: u32 = 32;
const H: u32 = 24;
const SPP: u32 = 8;

fn part(dir: &Path, name: &str, extra: &[&str]) -> Part {
    let out: PathBuf = dir.join(format!("{name}.exr"));
    let (code, stderr) = render_cornell(W, H, SPP, &out, extra);
    assert_eq!(code, 0, "{extra:?}: {stderr}");
    read_part(&out).unwrap()
}

#[test]
fn the_cpu_backend_renders_the_gpu_image_and_merges_with_gpu_parts() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("cpu-device");
    let gpu = part(&dir, "gpu", &["--shard", "0/1"]);
    let cpu = part(&dir, "cpu", &["--shard", "0/1", "--device", "cpu"]);
    let pixels = (W * H) as usize;
    let agree = agreeing_pixels(&cpu, &gpu);
    assert!(
        agree * 100 >= pixels * 98,
        "only {agree} of {pixels} pixels agree between the CPU and the GPU"
    );
    // The denoiser's guides (first-hit albedo, normal, directly seen light) are the GPU's too.
    for (name, c, g) in [
        ("albedo", &cpu.guides.albedo, &gpu.guides.albedo),
        ("normal", &cpu.guides.normal, &gpu.guides.normal),
        ("emission", &cpu.guides.emission, &gpu.guides.emission),
    ] {
        assert_eq!(c.len(), pixels, "{name}: the CPU part has no guides");
        let close = c
            .iter()
            .zip(g)
            .filter(|(a, b)| {
                a.iter()
                    .zip(*b)
                    .all(|(x, y)| (x - y).abs() <= 1e-3 * x.abs().max(1.0))
            })
            .count();
        assert!(
            close * 100 >= pixels * 98,
            "{name}: {close} of {pixels} pixels agree"
        );
    }
    // Half the samples on each: the merged frame is the one-machine frame.
    let first = dir.join("first.exr");
    let (code, stderr) = render_cornell(W, H, SPP, &first, &["--shard", "0/2", "--device", "cpu"]);
    assert_eq!(code, 0, "{stderr}");
    let second = dir.join("second.exr");
    let (code, stderr) = render_cornell(W, H, SPP, &second, &["--shard", "1/2"]);
    assert_eq!(code, 0, "{stderr}");
    let merged = merge_parts(&first, &second, &dir.join("merged.exr"));
    let agree = agreeing_pixels(&merged, &gpu);
    assert!(
        agree * 100 >= pixels * 98,
        "only {agree} of {pixels} pixels of the merged CPU and GPU halves agree with the GPU frame"
    );
}

#[test]
fn the_cpu_backend_refuses_flags_that_choose_a_gpu() {
    let dir = temp_dir("cpu-refuses");
    let out = dir.join("out.png");
    for (flags, named) in [
        (&["--adapter", "cpu"][..], "--adapter"),
        (&["--kernel", "megakernel"], "--kernel"),
        (&["--trace", "hw"], "--trace hw"),
    ] {
        let mut args = vec!["render", "--device", "cpu", "-o", out.to_str().unwrap()];
        args.extend(flags);
        let (code, _, stderr) = rt_cli(&args);
        assert_ne!(code, 0, "{flags:?} was accepted");
        assert!(
            stderr.contains(named) && stderr.contains("--device gpu"),
            "{flags:?}: {stderr}"
        );
        assert!(!out.exists(), "{flags:?} wrote an image");
    }
}

/// The GPU path's stops and extras on the CPU: adaptive sampling gives pixels their own counts
/// (the EXR keeps them), a noise target and a time limit stop the render, and `--denoise` writes
/// the denoised copy from the CPU's own guides. Needs no GPU.
#[test]
fn the_cpu_backend_samples_adaptively_stops_on_noise_and_time_and_denoises() {
    let dir = temp_dir("cpu-features");
    let run = |name: &str, flags: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "render",
            "--device",
            "cpu",
            "--width",
            "24",
            "--height",
            "18",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(flags);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{flags:?}: {stderr}");
        (out, stderr)
    };
    let (_, stderr) = run("adaptive.exr", &["--spp", "256", "--adaptive", "0.2"]);
    assert!(
        stderr.contains("adaptive:") && stderr.contains("device:         CPU"),
        "{stderr}"
    );
    let (_, stderr) = run("noise.exr", &["--spp", "4096", "--noise-target", "0.2"]);
    assert!(stderr.contains("stopped by noise target"), "{stderr}");
    let (_, stderr) = run("time.exr", &["--spp", "1000000", "--time-limit", "0.5"]);
    assert!(stderr.contains("stopped by time limit"), "{stderr}");
    let (out, stderr) = run("denoised.png", &["--spp", "4", "--denoise=atrous"]);
    let denoised = out.with_file_name("denoised.denoised.png");
    assert!(denoised.exists(), "{stderr}");
}

/// `--device auto` renders with a hardware GPU where there is one and with the CPU backend
/// otherwise (lavapipe does not count), and says which and why; `--adapter` makes it a GPU.
#[test]
fn auto_picks_a_backend_and_says_why() {
    let dir = temp_dir("cpu-auto");
    let out = dir.join("auto.png");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--device",
            "auto",
            "--width",
            "16",
            "--height",
            "12",
            "--spp",
            "2",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let (code, _, stderr) = rt_cli(&args);
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        stderr
    };
    let hardware = rt_gpu::hardware_gpu();
    let stderr = render(&[]);
    let expected = match &hardware {
        Some(_) => "device:         GPU (auto: hardware GPU",
        None => "device:         CPU (native backend",
    };
    assert!(
        stderr.contains(expected) && stderr.contains("auto:"),
        "{hardware:?}: {stderr}"
    );
    if has_gpu() {
        let stderr = render(&["--adapter", "lavapipe"]);
        assert!(
            stderr.contains(
                "device:         GPU (auto: --adapter, --kernel or --trace hw asks for a GPU)"
            ),
            "{stderr}"
        );
    }
}

/// The CPU backend's image does not depend on its thread count: one thread and two give the same
/// sums bit for bit (each pixel's samples are its own, and fixed-point addition is exact).
#[test]
fn the_cpu_image_is_the_same_whatever_the_thread_count() {
    let dir = temp_dir("cpu-threads");
    let render = |threads: &str| {
        let out = dir.join(format!("threads-{threads}.exr"));
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_rt-cli"))
            .args([
                "render", "--device", "cpu", "--width", "20", "--height", "14", "--spp", "6",
                "--shard", "0/1", "-o",
            ])
            .arg(&out)
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        read_part(&out).unwrap()
    };
    let (one, two) = (render("1"), render("2"));
    assert_eq!(one.sums, two.sums);
    assert_eq!(one.counts, two.counts);
}

/// `converge --device cpu` measures the CPU backend's images against a reference, step by step,
/// and its error falls as samples are added.
#[test]
fn converge_runs_on_the_cpu_backend() {
    let dir = temp_dir("cpu-converge");
    let reference = dir.join("reference.exr");
    let (code, _, stderr) = rt_cli(&[
        "render",
        "--device",
        "cpu",
        "--width",
        "16",
        "--height",
        "12",
        "--spp",
        "256",
        "-o",
        reference.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, stdout, stderr) = rt_cli(&[
        "converge",
        "--device",
        "cpu",
        "--width",
        "16",
        "--height",
        "12",
        "--max-spp",
        "16",
        "--reference",
        reference.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("CPU (native backend"), "{stderr}");
    let errors: Vec<f64> = stdout
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(errors.len(), 5, "{stdout}");
    assert!(
        errors[4] < errors[0] / 4.0,
        "the error does not fall: {stdout}"
    );
}

/// A layer's values by channel name, as `render` or `merge` wrote the EXR.
fn exr_channels(path: &Path) -> std::collections::HashMap<String, Vec<f32>> {
    let layers = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    let channels = &layers.layer_data[0].channel_data.list;
    channels
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect()
}

/// Alpha and passes survive a split render: three CPU shards of a transparent render of the
/// Cornell box with a shadow catcher floor and every pass, merged, give the whole render's alpha,
/// depth and positions (to the rounding of means merged in another order) and its object and
/// material ids exactly (the frame's first sample's), as EXR layers and as a PNG's alpha.
#[test]
fn shards_keep_alpha_and_passes_through_the_merge() {
    let dir = temp_dir("cpu-shard-layers");
    let flags = [
        "--device",
        "cpu",
        "--shadow-catcher",
        "floor",
        "--aov",
        "depth,normal,albedo,position,object,material",
    ];
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let (code, stderr) = render_cornell(20, 16, 6, &out, &[&flags[..], extra].concat());
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        out
    };
    let whole = render("whole.exr", &[]);
    let parts: Vec<PathBuf> = (0..3)
        .map(|i| render(&format!("part{i}.exr"), &["--shard", &format!("{i}/3")]))
        .collect();
    let part_refs: Vec<&Path> = parts.iter().map(PathBuf::as_path).collect();
    // Merged in another order than the samples': the ids still come from the first shard.
    let merge = |parts: &[&Path], out: &Path| {
        let mut args = vec!["merge"];
        args.extend(parts.iter().map(|p| p.to_str().unwrap()));
        args.extend(["-o", out.to_str().unwrap()]);
        let (code, _, stderr) = rt_cli(&args);
        (code, stderr)
    };
    let merged = dir.join("merged.exr");
    let (code, stderr) = merge(&[part_refs[2], part_refs[0], part_refs[1]], &merged);
    assert_eq!(code, 0, "{stderr}");
    let (a, b) = (exr_channels(&whole), exr_channels(&merged));
    for name in [
        "A",
        "depth.Z",
        "position.X",
        "position.Y",
        "normal.Y",
        "albedo.R",
    ] {
        let (x, y) = (&a[name], &b[name]);
        assert_eq!(x.len(), 320, "{name}");
        for (i, (p, q)) in x.iter().zip(y).enumerate() {
            assert!(
                (p - q).abs() <= 1e-4 * p.abs().max(1.0),
                "{name} at pixel {i}: whole {p}, merged {q}"
            );
        }
    }
    assert_eq!(a["object.ID"], b["object.ID"]);
    assert_eq!(a["material.ID"], b["material.ID"]);
    assert!(a["A"].iter().any(|&x| x < 0.5), "the catcher floor");
    let png = dir.join("merged.png");
    let (code, stderr) = merge(&part_refs, &png);
    assert!(
        code != 0 && stderr.contains(".exr"),
        "passes in a PNG: {stderr}"
    );
    // Alpha alone merges into a PNG too.
    let catcher = ["--device", "cpu", "--shadow-catcher", "floor"];
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let (code, stderr) = render_cornell(20, 16, 6, &out, &[&catcher[..], extra].concat());
        assert_eq!(code, 0, "{extra:?}: {stderr}");
        out
    };
    let whole = image::open(render("whole.png", &[])).unwrap().to_rgba8();
    let parts: Vec<PathBuf> = (0..2)
        .map(|i| render(&format!("alpha{i}.exr"), &["--shard", &format!("{i}/2")]))
        .collect();
    let (code, stderr) = merge(&[&parts[0], &parts[1]], &png);
    assert_eq!(code, 0, "{stderr}");
    let merged = image::open(&png).unwrap().to_rgba8();
    for (p, q) in whole.pixels().zip(merged.pixels()) {
        assert!(
            p.0[3].abs_diff(q.0[3]) <= 1,
            "alpha {} vs {}",
            p.0[3],
            q.0[3]
        );
    }
}
