//! `rt-cli` as a user runs it: renders, info, and bad input → one-line error, exit code 2, no panic.
//!
//! `renders.rs` holds renders, `info` and bad input, `convergence.rs` noise targets, time limits
//! and `converge`, `tiles_and_kernels.rs` tiles, kernels and ray queries, `faults_and_denoising.rs`
//! device faults and denoising, `transparent_regions.rs` a transparent region pasted back.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

#[path = "../common/mod.rs"]
mod common;
mod convergence;
mod faults_and_denoising;
mod renders;
mod tiles_and_kernels;
mod transparent_regions;

use common::{has_gpu, render_cornell, render_cornell_with_env, rt_cli, temp_dir};
