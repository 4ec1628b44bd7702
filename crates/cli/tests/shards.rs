//! Renders split across machines: `render --shard` / `--sample-range` parts and `merge`, which must
//! give the one-machine render bit for bit and refuse what does not belong together.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

mod common;
use std::path::{Path, PathBuf};

use common::{has_gpu, render_cornell, render_cornell_with_env, rt_cli, temp_dir};
use rt_core::part::{Part, read_part};

const W: u32 = 32;
const H: u32 = 24;
const SPP: u32 = 9;

/// A part rendered on the GPU (the suite's subject: the GPU kernels' parts; `cpu_device.rs`
/// merges CPU parts with them).
fn shard(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(format!("{name}.exr"));
    let extra = [&["--device", "gpu"], extra].concat();
    let (code, stderr) = render_cornell(W, H, SPP, &out, &extra);
    assert_eq!(code, 0, "{extra:?}: {stderr}");
    out
}

fn merge(parts: &[&Path], out: &Path, extra: &[&str]) -> (i32, String) {
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap()]);
    args.extend(extra);
    let (code, _, stderr) = rt_cli(&args);
    (code, stderr)
}

/// The samples themselves: what must be equal bit for bit (headers differ in their notes).
fn same_samples(a: &Part, b: &Part) -> bool {
    a.counts == b.counts && a.sums == b.sums && a.pixels() == b.pixels()
}

/// R, G, B of an EXR as `image` reads them.
fn exr_rgb(path: &Path) -> Vec<f32> {
    let image = image::open(path).unwrap().into_rgb32f();
    image.into_raw()
}

#[test]
fn merged_shards_are_the_one_machine_render_bit_for_bit() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("shards");
    let whole = read_part(&shard(&dir, "whole", &["--shard", "0/1"])).unwrap();
    assert!(whole.is_complete());
    // Four shards, one of them traced by the megakernel (the same samples without delta lights).
    let parts: Vec<PathBuf> = (0..4)
        .map(|i| {
            let index = format!("{i}/4");
            let mut extra = vec!["--shard", index.as_str()];
            if i == 1 {
                extra.extend(["--kernel", "megakernel"]);
            }
            shard(&dir, &format!("shard{i}"), &extra)
        })
        .collect();
    let first = read_part(&parts[0]).unwrap();
    assert_eq!(first.header.sample_ranges, [[0, 2]]);
    assert!(
        !same_samples(&first, &whole),
        "a shard holds fewer samples than the frame"
    );
    let merged = dir.join("merged.exr");
    let refs: Vec<&Path> = parts.iter().map(PathBuf::as_path).collect();
    let (code, stderr) = merge(&refs, &merged, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("the whole frame"), "{stderr}");
    let merged_part = read_part(&merged).unwrap();
    assert!(
        same_samples(&merged_part, &whole),
        "4 merged shards differ from the one-machine render"
    );

    // Merges associate: (0+1) + (2+3), and a merged part merges again.
    let (left, right) = (dir.join("left.exr"), dir.join("right.exr"));
    assert_eq!(merge(&refs[..2], &left, &["--allow-partial"]).0, 0);
    assert_eq!(merge(&refs[2..], &right, &["--allow-partial"]).0, 0);
    let nested = dir.join("nested.exr");
    assert_eq!(merge(&[&right, &left], &nested, &[]).0, 0);
    assert!(same_samples(&read_part(&nested).unwrap(), &whole));

    // Uneven sample ranges give the same frame too.
    let ranges: Vec<PathBuf> = ["0..1", "1..7", "7..9"]
        .iter()
        .enumerate()
        .map(|(i, r)| shard(&dir, &format!("range{i}"), &["--sample-range", r]))
        .collect();
    let refs: Vec<&Path> = ranges.iter().map(PathBuf::as_path).collect();
    let from_ranges = dir.join("from_ranges.exr");
    assert_eq!(merge(&refs, &from_ranges, &[]).0, 0);
    assert!(same_samples(&read_part(&from_ranges).unwrap(), &whole));

    // And the plain render's colour and variance (what a user compares) are the merged ones.
    let plain = dir.join("plain.exr");
    let (code, stderr) = render_cornell(W, H, SPP, &plain, &["--device", "gpu"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(exr_rgb(&plain), exr_rgb(&merged));
    let merged_png = dir.join("merged.png");
    let (code, stderr) = merge(&refs, &merged_png, &["--denoise"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(dir.join("merged.denoised.png").is_file(), "{stderr}");
    let plain_png = dir.join("plain.png");
    assert_eq!(
        render_cornell(W, H, SPP, &plain_png, &["--device", "gpu"]).0,
        0
    );
    assert_eq!(
        image::open(&plain_png).unwrap().into_rgb8().into_raw(),
        image::open(&merged_png).unwrap().into_rgb8().into_raw()
    );

    // A duplicated task writes the same file again, byte for byte.
    let again = shard(&dir, "shard0-again", &["--shard", "0/4"]);
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&parts[0]).unwrap()
    );
}

#[test]
fn parts_that_do_not_belong_together_are_refused() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("shards-refused");
    let a = shard(&dir, "a", &["--shard", "0/2"]);
    let b = shard(&dir, "b", &["--shard", "1/2"]);
    let out = dir.join("out.exr");
    let refused = |parts: &[&Path], says: &[&str]| {
        let (code, stderr) = merge(parts, &out, &[]);
        assert_eq!(code, 2, "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        for s in says {
            assert!(stderr.contains(s), "expected {s:?} in: {stderr}");
        }
    };
    let other_seed = shard(&dir, "seed", &["--shard", "1/2", "--seed", "7"]);
    refused(&[&a, &other_seed], &["settings_hash", "a.exr", "seed.exr"]);
    let other_scene = shard(
        &dir,
        "scene",
        &["--shard", "1/2", "--ambient", "0.1,0.1,0.1"],
    );
    refused(&[&a, &other_scene], &["settings_hash"]);
    let glb = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/BoxTextured.glb");
    let other_file = dir.join("glb.exr");
    let (w, h, n) = (W.to_string(), H.to_string(), SPP.to_string());
    let (code, _, stderr) = rt_cli(&[
        "render",
        glb.to_str().unwrap(),
        "--width",
        &w,
        "--height",
        &h,
        "--spp",
        &n,
        "--shard",
        "1/2",
        "-o",
        other_file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    refused(&[&a, &other_file], &["scene_hash", "another scene"]);
    let overlapping = shard(&dir, "overlap", &["--sample-range", "3..9"]);
    refused(&[&a, &overlapping], &["overlap", "a.exr", "overlap.exr"]);
    refused(&[&a], &["missing 4..9", "--allow-partial"]);
    refused(&[&a, &a], &["overlap"]);

    let truncated = dir.join("truncated.exr");
    let bytes = std::fs::read(&b).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() * 2 / 3]).unwrap();
    refused(
        &[&a, &truncated],
        &["truncated.exr", "truncated or damaged"],
    );
    let plain = dir.join("plain.exr");
    assert_eq!(render_cornell(W, H, SPP, &plain, &[]).0, 0);
    refused(&[&a, &plain], &["plain.exr", "not a part"]);
    assert!(!out.exists(), "a refused merge wrote its output");

    // Shards are EXR parts of a fixed range, denoised only after the merge.
    for (extra, says) in [
        (vec!["--shard", "0/2"], "name it .exr"),
        (vec!["--shard", "0/2", "--time-limit", "1"], "fixed range"),
        (
            vec!["--sample-range", "5..20"],
            "past the frame's 9 samples",
        ),
        (vec!["--shard", "2/2"], "below the count"),
    ] {
        let png = dir.join("shard.png");
        let target = if says == "name it .exr" { &png } else { &out };
        let (code, stderr) = render_cornell(W, H, SPP, target, &extra);
        assert_eq!(code, 2, "{extra:?}: {stderr}");
        assert!(stderr.contains(says), "{extra:?}: {stderr}");
    }
}

#[test]
fn a_shard_that_dies_leaves_no_part_and_a_rerun_completes_the_set() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("shards-killed");
    let a = shard(&dir, "a", &["--shard", "0/2"]);
    let b = dir.join("b.exr");
    // Killed by the batch system mid-render.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_rt-cli"))
        .args([
            "render", "--device", "gpu", "--width", "256", "--height", "256", "--spp", "100000",
        ])
        .args(["--shard", "1/2", "-o"])
        .arg(&b)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!b.exists(), "a killed shard left a part");
    // The GPU lost mid-render: an error, and still no part.
    let (code, stderr) = render_cornell_with_env(
        W,
        H,
        SPP,
        &b,
        &["--device", "gpu", "--shard", "1/2"],
        &[("RT_FAULT_LOSE_DEVICE_AFTER_BATCHES", "0")],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("no part was written"), "{stderr}");
    assert!(!b.exists());
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n != "a.exr")
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    // The rerun completes the set.
    shard(&dir, "b", &["--shard", "1/2"]);
    let out = dir.join("frame.exr");
    let (code, stderr) = merge(&[&a, &b], &out, &[]);
    assert_eq!(code, 0, "{stderr}");
}
