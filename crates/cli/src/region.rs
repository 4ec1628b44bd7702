//! `render --region X0,Y0,X1,Y1`: only a window of the image is rendered and written (its pixels
//! take the samples the whole image takes there: `RenderSettings::film_window`), or with
//! `--into FILE` pasted into an earlier render of the whole image (with its alpha, when the render
//! is transparent).

use std::path::Path;

use anyhow::{Context, Result};
use rt_core::output::{ImageFormat, View};
use rt_core::scene::{FilmWindow, RenderSettings};

/// Parses "X0,Y0,X1,Y1" (pixels; X1 and Y1 excluded).
pub fn parse_region(s: &str) -> Result<[u32; 4], String> {
    let numbers: Vec<u32> = s
        .split(',')
        .map(|t| t.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected X0,Y0,X1,Y1 in pixels, got '{s}'"))?;
    let [x0, y0, x1, y1] = numbers[..] else {
        return Err(format!("expected four numbers X0,Y0,X1,Y1, got '{s}'"));
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!(
            "'{s}': X0 < X1 and Y0 < Y1 (pixels, X1 and Y1 excluded)"
        ));
    }
    Ok([x0, y0, x1, y1])
}

/// Makes the settings render only `region` of the image they describe.
pub fn apply(settings: &mut RenderSettings, region: [u32; 4]) -> Result<()> {
    settings
        .crop_to_region(region)
        .map_err(|e| anyhow::anyhow!("--region: {e}"))
}

/// Pastes the rendered window (`pixels`, `window`) into `into`, an image of the whole film, and
/// saves the result as `output` (atomically; it may be `into` itself). EXR pastes linear values;
/// 8-bit formats paste the window as `view` shows it.
pub fn compose_into(
    into: &Path,
    output: &Path,
    window: FilmWindow,
    size: [u32; 2],
    pixels: &[[f32; 4]],
    view: View,
) -> Result<()> {
    let format = ImageFormat::from_path(output)?;
    let base = open_whole(into, window)?;
    let place = placement(window, size);
    let bytes = if format == ImageFormat::Exr {
        let mut whole = base.to_rgb32f();
        for (i, p) in pixels.iter().enumerate() {
            let (x, y) = place(i);
            whole.put_pixel(x, y, image::Rgb([p[0], p[1], p[2]]));
        }
        let rgb: Vec<[f32; 3]> = whole.pixels().map(|p| p.0).collect();
        rt_core::output::encode_image(format, whole.width(), whole.height(), &rgb, view)?
    } else {
        let mut whole = base.to_rgb8();
        for (i, p) in pixels.iter().enumerate() {
            let (x, y) = place(i);
            whole.put_pixel(x, y, image::Rgb(view.to_srgb8([p[0], p[1], p[2]])));
        }
        let mut out = std::io::Cursor::new(Vec::new());
        let kind = image::ImageFormat::from_path(output)
            .with_context(|| format!("saving {}", output.display()))?;
        whole
            .write_to(&mut out, kind)
            .with_context(|| format!("encoding {}", output.display()))?;
        out.into_inner()
    };
    rt_core::output::write_atomically(output, &bytes)?;
    Ok(())
}

/// `compose_into` for a transparent render (`--transparent`): the window's colour and alpha
/// (`coverage`) pasted over the whole image's, which gains an alpha where it had none (opaque).
/// EXR keeps linear colour premultiplied by alpha, PNG straight alpha through `view`, as
/// `rt_core::output::encode_with_alpha` writes them.
pub fn compose_into_with_alpha(
    into: &Path,
    output: &Path,
    window: FilmWindow,
    size: [u32; 2],
    (pixels, coverage): (&[[f32; 4]], &[f32]),
    view: View,
) -> Result<()> {
    let format = ImageFormat::from_path(output)?;
    let base = open_whole(into, window)?;
    let place = placement(window, size);
    let mut out = std::io::Cursor::new(Vec::new());
    let encoded = match format {
        ImageFormat::Exr => {
            let mut whole = base.to_rgba32f();
            for (i, (p, &alpha)) in pixels.iter().zip(coverage).enumerate() {
                let (x, y) = place(i);
                whole.put_pixel(x, y, image::Rgba([p[0], p[1], p[2], alpha]));
            }
            whole.write_to(&mut out, image::ImageFormat::OpenExr)
        }
        ImageFormat::Png => {
            let mut whole = base.to_rgba8();
            for (i, (p, &alpha)) in pixels.iter().zip(coverage).enumerate() {
                let (x, y) = place(i);
                whole.put_pixel(
                    x,
                    y,
                    image::Rgba(view.straight_rgba8([p[0], p[1], p[2]], alpha)),
                );
            }
            whole.write_to(&mut out, image::ImageFormat::Png)
        }
        _ => anyhow::bail!("--transparent needs an output with alpha: .png or .exr"),
    };
    encoded.with_context(|| format!("encoding {}", output.display()))?;
    rt_core::output::write_atomically(output, &out.into_inner())?;
    Ok(())
}

/// The image `--into` names, checked to be the whole film the region belongs to.
fn open_whole(into: &Path, window: FilmWindow) -> Result<image::DynamicImage> {
    let base = image::open(into).with_context(|| format!("--into {}", into.display()))?;
    if (base.width(), base.height()) != (window.film_width, window.film_height) {
        anyhow::bail!(
            "--into {}: it is {}x{}, the image the region belongs to is {}x{}",
            into.display(),
            base.width(),
            base.height(),
            window.film_width,
            window.film_height
        );
    }
    Ok(base)
}

/// Where the window's pixel `i` (row-major in a `size` window) lies in the whole film.
fn placement(window: FilmWindow, size: [u32; 2]) -> impl Fn(usize) -> (u32, u32) {
    move |i| {
        let (x, y) = (i as u32 % size[0], i as u32 / size[0]);
        (window.x + x, window.y + y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_parse_and_fit_the_image() {
        assert_eq!(parse_region("1, 2,30,40"), Ok([1, 2, 30, 40]));
        assert!(parse_region("5,5,5,9").is_err() && parse_region("1,2,3").is_err());
        let mut settings = RenderSettings {
            width: 64,
            height: 32,
            ..RenderSettings::default()
        };
        assert!(apply(&mut settings.clone(), [0, 0, 65, 10]).is_err());
        apply(&mut settings, [8, 4, 24, 20]).unwrap();
        assert_eq!((settings.width, settings.height), (16, 16));
        let window = settings.film_window.unwrap();
        assert_eq!(
            (window.x, window.y, window.film_width, window.film_height),
            (8, 4, 64, 32)
        );
        assert!(settings.validate().is_ok());
    }
}
