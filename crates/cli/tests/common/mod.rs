//! Running rt-cli from the tests, as a user would.
#![allow(
    dead_code,
    reason = "each test binary uses its own share of the helpers"
)]
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

use std::process::Command;

pub fn rt_cli(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rt-cli"))
        .args(args)
        .output()
        .expect("run rt-cli");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `rt-cli render` of the embedded Cornell box at `width` x `height` and `spp` into `out`, with
/// `extra` arguments; returns the exit code and stderr.
pub fn render_cornell(
    width: u32,
    height: u32,
    spp: u32,
    out: &std::path::Path,
    extra: &[&str],
) -> (i32, String) {
    render_cornell_with_env(width, height, spp, out, extra, &[])
}

/// `render_cornell` with environment variables set for rt-cli.
pub fn render_cornell_with_env(
    width: u32,
    height: u32,
    spp: u32,
    out: &std::path::Path,
    extra: &[&str],
    env: &[(&str, &str)],
) -> (i32, String) {
    let (w, h, n) = (width.to_string(), height.to_string(), spp.to_string());
    let result = Command::new(env!("CARGO_BIN_EXE_rt-cli"))
        .args(["render", "--width", &w, "--height", &h, "--spp", &n, "-o"])
        .arg(out)
        .args(extra)
        .envs(env.iter().copied())
        .output()
        .expect("run rt-cli");
    (
        result.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&result.stderr).into(),
    )
}

pub fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("rt-cli-test-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Whether the GPU tests here can run, under the suites' one policy (`GpuContext::for_tests`):
/// without an adapter they fail under CI and are skipped with a message elsewhere.
pub fn has_gpu() -> bool {
    static FOUND: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FOUND.get_or_init(|| rt_gpu::GpuContext::for_tests().is_some())
}

/// How many pixels of two parts of the same samples agree to rounding. The twins compute each
/// sample with the same random numbers, but a last-bit difference may send a path another way
/// (another lobe, the other side of an edge): such pixels hold a different, equally valid sample
/// and are counted, not compared.
pub fn agreeing_pixels(a: &rt_core::part::Part, b: &rt_core::part::Part) -> usize {
    assert_eq!(a.counts, b.counts, "sample counts");
    a.pixels()
        .iter()
        .zip(b.pixels())
        .filter(|(p, q)| {
            p.iter()
                .zip(q)
                .all(|(x, y)| (x - y).abs() <= 1e-4 * x.abs().max(y.abs()) + 1e-7)
        })
        .count()
}

/// `rt-cli merge` of the parts `first` and `second` into `merged`, read back (it must be whole).
pub fn merge_parts(
    first: &std::path::Path,
    second: &std::path::Path,
    merged: &std::path::Path,
) -> rt_core::part::Part {
    let (code, _, stderr) = rt_cli(&[
        "merge",
        first.to_str().unwrap(),
        second.to_str().unwrap(),
        "-o",
        merged.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let part = rt_core::part::read_part(merged).unwrap();
    assert!(part.is_complete());
    part
}
