//! `rt-cli` as a user runs it: renders, info, and bad input → one-line error, exit code 2, no panic.
//!
//! `renders.rs` holds renders, `info` and bad input, `convergence.rs` noise targets, time limits
//! and `converge`, `tiles_and_kernels.rs` tiles, kernels and ray queries, `faults_and_denoising.rs`
//! device faults and denoising, `transparent_regions.rs` a transparent region pasted back,
//! `cryptomatte.rs` Cryptomatte's layers, `animation.rs` animations and turntables.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

mod animation;
#[path = "../common/mod.rs"]
mod common;
mod convergence;
mod cryptomatte;
mod faults_and_denoising;
mod integrators;
mod renders;
mod tiles_and_kernels;
mod transparent_regions;

use common::{has_gpu, render_cornell, render_cornell_with_env, rt_cli, temp_dir};

/// Writes a camera file into `dir` that looks at the Cornell box from outside it: the box fills
/// the middle of the image, the background the rest (for alpha).
fn outside_camera(dir: &std::path::Path) -> std::path::PathBuf {
    let camera = dir.join("outside.json");
    std::fs::write(
        &camera,
        r#"{"from": [278, 273, -1600], "to": [278, 273, 0], "vfov": 40}"#,
    )
    .unwrap();
    camera
}
