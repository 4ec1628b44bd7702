//! `rt-cli compare`: error metrics of an image against a reference.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rt_core::metrics::{RgbImage, compare};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image to judge (EXR for exact values; 8-bit images are decoded from sRGB).
    image: PathBuf,
    /// The reference; box-downsampled when it is an integer multiple of the image's size.
    reference: PathBuf,
}

pub fn run(args: CompareArgs) -> Result<()> {
    let image = RgbImage::load(&args.image)?;
    let reference = RgbImage::load(&args.reference)?;
    let e = compare(&image, &reference).map_err(anyhow::Error::msg)?;
    println!("relMSE:      {:.6e}", e.rel_mse);
    println!("RMSE:        {:.6e}", e.rmse);
    println!(
        "mean ratio:  {:.5} {:.5} {:.5}",
        e.mean_ratio[0], e.mean_ratio[1], e.mean_ratio[2]
    );
    Ok(())
}
