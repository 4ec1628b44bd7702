//! `render --device all`: the GPU (lavapipe in tests) and the native CPU backend on one frame,
//! dealt sample ranges by a shared counter. Its frame is the one-device frame (the same samples,
//! summed exactly), its parts merge with any other, and what it cannot do is refused clearly.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

mod common;
use std::path::Path;

use common::{agreeing_pixels, has_gpu, merge_parts, render_cornell, rt_cli, temp_dir};
use rt_core::part::{Part, read_part};

const W: u32 = 32;
const H: u32 = 24;
const SPP: u32 = 16;

fn part(dir: &Path, name: &str, extra: &[&str]) -> (Part, String) {
    let out = dir.join(format!("{name}.exr"));
    let (code, stderr) = render_cornell(W, H, SPP, &out, extra);
    assert_eq!(code, 0, "{extra:?}: {stderr}");
    (read_part(&out).unwrap(), stderr)
}

/// z of the difference of two images' mean luminance, each mean's variance from its pixels'
/// sample variances (mean squared luminance in the fourth channel).
fn mean_z(a: &Part, b: &Part) -> f64 {
    let stats = |part: &Part| {
        let pixels = part.pixels();
        let n = pixels.len() as f64;
        pixels
            .iter()
            .zip(&part.counts)
            .fold((0.0, 0.0), |(m, v), (p, &c)| {
                let y =
                    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
                let variance = (f64::from(p[3]) - y * y).max(0.0) / f64::from(c.max(1));
                (m + y / n, v + variance / (n * n))
            })
    };
    let ((ma, va), (mb, vb)) = (stats(a), stats(b));
    (ma - mb) / (va + vb).sqrt().max(1e-12)
}

/// Both devices take samples, the frame agrees pixel by pixel with the CPU backend's (and its
/// mean in a Z-test), and a `--device all` part merges with a CPU part into the same frame.
#[test]
fn both_devices_render_the_one_device_frame_and_merge() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("all-devices");
    let (all, stderr) = part(&dir, "all", &["--shard", "0/1", "--device", "all"]);
    let shares = stderr
        .lines()
        .find(|l| l.starts_with("device:"))
        .unwrap_or_default()
        .to_string();
    // "... samples per pixel: GPU n, CPU m)"
    let taken = |device: &str| -> u32 {
        let after = shares
            .split("samples per pixel:")
            .nth(1)
            .unwrap_or_default();
        let at = after
            .find(device)
            .map_or(after.len(), |i| i + device.len() + 1);
        let digits: String = after[at..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        digits.parse().unwrap_or(0)
    };
    assert!(
        shares.contains("--device all") && taken("GPU") > 0 && taken("CPU") > 0,
        "both devices should take samples: {shares}"
    );
    assert_eq!(taken("GPU") + taken("CPU"), SPP, "{shares}");
    let (cpu, _) = part(&dir, "cpu", &["--shard", "0/1", "--device", "cpu"]);
    let pixels = (W * H) as usize;
    let agree = agreeing_pixels(&all, &cpu);
    assert!(
        agree * 100 >= pixels * 98,
        "only {agree} of {pixels} pixels agree with the CPU frame"
    );
    let z = mean_z(&all, &cpu);
    assert!(z.abs() < 4.0, "image means differ: z = {z:.2}");
    // The first half on both devices, the second on the CPU: merged, the CPU frame.
    let (first, second) = (dir.join("first.exr"), dir.join("second.exr"));
    let (code, stderr) = render_cornell(W, H, SPP, &first, &["--shard", "0/2", "--device", "all"]);
    assert_eq!(code, 0, "{stderr}");
    let (code, stderr) = render_cornell(W, H, SPP, &second, &["--shard", "1/2", "--device", "cpu"]);
    assert_eq!(code, 0, "{stderr}");
    let merged = merge_parts(&first, &second, &dir.join("merged.exr"));
    let agree = agreeing_pixels(&merged, &cpu);
    assert!(
        agree * 100 >= pixels * 98,
        "only {agree} of {pixels} pixels of the merged halves agree with the CPU frame"
    );
}

/// What one frame on two devices cannot do is refused, naming the way out.
#[test]
fn both_devices_refuse_adaptive_sampling_and_other_commands() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("all-devices-refusals");
    let out = dir.join("noise.exr");
    let (code, stderr) = render_cornell(W, H, 64, &out, &["--device", "all", "--adaptive", "0.1"]);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("adaptive sampling") && stderr.contains("--device all"),
        "{stderr}"
    );
    let reference = dir.join("reference.exr");
    let (code, stderr) = render_cornell(W, H, 1, &reference, &["--device", "cpu"]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = rt_cli(&[
        "converge",
        "--device",
        "all",
        "--max-spp",
        "2",
        "--reference",
        reference.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("--device all is for `render`"), "{stderr}");
}
