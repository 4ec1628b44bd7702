//! Writing rendered images. EXR holds linear radiance as float (never tone-mapped); PNG, JPEG and
//! PPM hold `sRGB(view(balance · radiance · 2^exposure))` in 8 bits, `view` a plain clamp to [0, 1]
//! (`ViewTransform::Standard`), the Khronos PBR Neutral tone mapper or AgX, `balance` an optional
//! white balance (`display.rs`). Every save goes to a
//! temporary file in the same folder first and is renamed over the target, so a crash or a full
//! disk never leaves a half-written image where a good one was.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Jpeg,
    Ppm,
    Exr,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        Ok(match ext.as_str() {
            "png" => ImageFormat::Png,
            "jpg" | "jpeg" => ImageFormat::Jpeg,
            "ppm" => ImageFormat::Ppm,
            "exr" => ImageFormat::Exr,
            _ => {
                return Err(Error::File {
                    path: path.into(),
                    message: "unknown image type; use .png, .jpg, .ppm or .exr".into(),
                });
            }
        })
    }
}

/// sRGB transfer function (encode linear to display).
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB of a linear radiance value after `exposure_stops`.
#[cfg(test)]
fn tone_map_u8(c: f32, exposure_stops: f32) -> u8 {
    let v = (c * exposure_stops.exp2()).clamp(0.0, 1.0);
    let v = if v.is_nan() { 0.0 } else { v };
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

/// How linear radiance becomes display values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViewTransform {
    /// Clamp each channel to [0, 1]: exact below 1, highlights clip (the default, as before).
    #[default]
    Standard,
    /// The Khronos PBR Neutral tone mapper (Khronos Group, 2024,
    /// github.com/KhronosGroup/ToneMapping): colours below 0.76 keep their hue and value (up to a
    /// small black offset), highlights roll off smoothly towards white instead of clipping.
    KhronosPbrNeutral,
    /// AgX, Blender's default since 4.0 (`display::agx`): a wide latitude of about 16.5 stops,
    /// highlights that roll off and desaturate towards white instead of skewing in hue.
    Agx,
}

impl ViewTransform {
    pub const ALL: [ViewTransform; 3] = [
        ViewTransform::Standard,
        ViewTransform::KhronosPbrNeutral,
        ViewTransform::Agx,
    ];

    /// The name users see.
    pub fn label(self) -> &'static str {
        match self {
            ViewTransform::Standard => "Standard",
            ViewTransform::KhronosPbrNeutral => "Khronos PBR Neutral",
            ViewTransform::Agx => "AgX",
        }
    }
}

/// A view transform with an exposure in stops and a white balance (applied first).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct View {
    pub transform: ViewTransform,
    pub exposure_stops: f32,
    /// The colour temperature (kelvin) of the light that should display white; `None` (or 6500)
    /// leaves colours as rendered.
    pub white_balance_k: Option<f32>,
}

impl From<f32> for View {
    /// The plain clamp at this exposure.
    fn from(exposure_stops: f32) -> Self {
        View {
            transform: ViewTransform::Standard,
            exposure_stops,
            white_balance_k: None,
        }
    }
}

/// Khronos PBR Neutral, from the reference GLSL of its specification.
pub fn khronos_pbr_neutral(rgb: [f32; 3]) -> [f32; 3] {
    const START_COMPRESSION: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = rgb[0].min(rgb[1]).min(rgb[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = rgb.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START_COMPRESSION {
        return c;
    }
    let d = 1.0 - START_COMPRESSION;
    let new_peak = 1.0 - d * d / (peak + d - START_COMPRESSION);
    let c = c.map(|v| v * new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v + (new_peak - v) * g)
}

impl View {
    /// `to_srgb8` of every pixel, as opaque RGBA bytes (what a texture upload takes).
    pub fn to_rgba8(&self, rgb: &[[f32; 3]]) -> Vec<u8> {
        let balance = self.balance();
        let mut bytes = Vec::with_capacity(rgb.len() * 4);
        for p in rgb {
            bytes.extend(self.balanced_to_srgb8(*p, balance));
            bytes.push(255);
        }
        bytes
    }

    /// The white balance's matrix (none without one).
    fn balance(&self) -> Option<[[f32; 3]; 3]> {
        self.white_balance_k
            .and_then(crate::display::white_balance_matrix)
    }

    /// 8-bit sRGB with straight alpha (PNG's) of a pixel whose linear colour is premultiplied by
    /// its alpha `alpha` (a transparent render's: the background adds nothing).
    pub fn straight_rgba8(&self, premultiplied: [f32; 3], alpha: f32) -> [u8; 4] {
        let straight = if alpha > 0.0 {
            premultiplied.map(|v| v / alpha)
        } else {
            [0.0; 3]
        };
        let [r, g, b] = self.to_srgb8(straight);
        [r, g, b, (alpha.clamp(0.0, 1.0) * 255.0 + 0.5) as u8]
    }

    /// 8-bit sRGB of one linear RGB pixel (NaN and negative values show black).
    pub fn to_srgb8(&self, rgb: [f32; 3]) -> [u8; 3] {
        self.balanced_to_srgb8(rgb, self.balance())
    }

    fn balanced_to_srgb8(&self, rgb: [f32; 3], balance: Option<[[f32; 3]; 3]>) -> [u8; 3] {
        let exposure = self.exposure_stops.exp2();
        let rgb = rgb.map(|v| if v.is_finite() { v * exposure } else { 0.0 });
        let rgb = match balance {
            Some(m) => m.map(|row| row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2]),
            None => rgb,
        };
        let c = rgb.map(|v| v.max(0.0));
        let c = match self.transform {
            ViewTransform::Standard => c,
            ViewTransform::KhronosPbrNeutral => khronos_pbr_neutral(c),
            ViewTransform::Agx => crate::display::agx(c),
        };
        c.map(|v| (linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
    }
}

/// Encodes `rgb` (row-major, top row first) to bytes in `format`.
pub fn encode_image(
    format: ImageFormat,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    view: impl Into<View>,
) -> Result<Vec<u8>> {
    let view = view.into();
    let mut out = std::io::Cursor::new(Vec::new());
    let encode_err = |e: image::ImageError| Error::Scene(format!("encoding the image failed: {e}"));
    match format {
        ImageFormat::Exr => {
            let data: Vec<f32> = rgb.iter().flatten().copied().collect();
            let buffer = image::Rgb32FImage::from_raw(width, height, data)
                .ok_or_else(|| Error::Scene("image size does not match its pixels".into()))?;
            buffer
                .write_to(&mut out, image::ImageFormat::OpenExr)
                .map_err(encode_err)?;
        }
        _ => {
            let balance = view.balance();
            let data: Vec<u8> = rgb
                .iter()
                .flat_map(|&c| view.balanced_to_srgb8(c, balance))
                .collect();
            let buffer = image::RgbImage::from_raw(width, height, data)
                .ok_or_else(|| Error::Scene("image size does not match its pixels".into()))?;
            let f = match format {
                ImageFormat::Png => image::ImageFormat::Png,
                ImageFormat::Jpeg => image::ImageFormat::Jpeg,
                _ => image::ImageFormat::Pnm,
            };
            if format == ImageFormat::Ppm {
                let encoder = image::codecs::pnm::PnmEncoder::new(&mut out).with_subtype(
                    image::codecs::pnm::PnmSubtype::Pixmap(
                        image::codecs::pnm::SampleEncoding::Binary,
                    ),
                );
                image::ImageEncoder::write_image(
                    encoder,
                    &buffer,
                    width,
                    height,
                    image::ExtendedColorType::Rgb8,
                )
                .map_err(encode_err)?;
            } else {
                buffer.write_to(&mut out, f).map_err(encode_err)?;
            }
        }
    }
    Ok(out.into_inner())
}

/// The variance of each pixel's estimate of luminance, s²/n, from the renderer's per-pixel means
/// of luminance (`rgb`) and of squared luminance (`[3]`) after each pixel's samples (`counts`; s²
/// with Bessel's correction). Zero below two samples.
pub fn pixel_variance(pixels: &[[f32; 4]], counts: SampleCounts) -> Vec<f32> {
    pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let n = counts.at(i);
            if n < 2 {
                return 0.0;
            }
            let n = f64::from(n);
            let m = 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
            let s2 = (f64::from(p[3]) - m * m).max(0.0) * n / (n - 1.0);
            (s2 / n) as f32
        })
        .collect()
}

/// How many samples each pixel of an accumulated image holds: all the same, or (adaptive
/// sampling) each its own.
#[derive(Clone, Copy, Debug)]
pub enum SampleCounts<'a> {
    Uniform(u32),
    PerPixel(&'a [u32]),
}

impl SampleCounts<'_> {
    /// Pixel `i`'s count.
    pub fn at(&self, i: usize) -> u32 {
        match self {
            SampleCounts::Uniform(n) => *n,
            SampleCounts::PerPixel(counts) => counts.get(i).copied().unwrap_or(0),
        }
    }
}

/// A linear EXR with the colour (R, G, B) and a `variance.Y` channel: the per-pixel variance of
/// the luminance estimate (see [`pixel_variance`]), for denoisers and adaptive sampling; with
/// per-pixel counts (adaptive sampling) also a `samples.Y` channel holding each pixel's count.
pub fn encode_exr_with_variance(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    counts: SampleCounts,
) -> Result<Vec<u8>> {
    encode_exr_layers(width, height, pixels, counts, &[], &[])
}

/// A named EXR channel beside the colour, one value per pixel (`depth.Z`, `CryptoObject00.r`).
pub type ExrChannel = (String, Vec<f32>);
/// A text attribute of an EXR's header (name, value).
pub type ExrAttribute = (String, String);

/// `encode_exr_with_variance` with more channels beside the colour: an alpha (`A`) and named
/// layers such as `depth.Z` or `normal.X` (render passes: `crate::passes`), one value per pixel;
/// and text attributes in the header (`metadata`: Cryptomatte's, `crate::cryptomatte`).
pub fn encode_exr_layers(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    counts: SampleCounts,
    extra: &[ExrChannel],
    metadata: &[ExrAttribute],
) -> Result<Vec<u8>> {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, Image, SmallVec, WritableImage};
    let size = width as usize * height as usize;
    if pixels.len() != size {
        return Err(Error::Scene("image size does not match its pixels".into()));
    }
    let channel = |c: usize| pixels.iter().map(|p| p[c]).collect::<Vec<f32>>();
    let mut channels = vec![
        AnyChannel::new("R", FlatSamples::F32(channel(0))),
        AnyChannel::new("G", FlatSamples::F32(channel(1))),
        AnyChannel::new("B", FlatSamples::F32(channel(2))),
        AnyChannel::new(
            "variance.Y",
            FlatSamples::F32(pixel_variance(pixels, counts)),
        ),
    ];
    for (name, values) in extra {
        if values.len() != size {
            return Err(Error::Scene(format!(
                "the {name} channel does not match the image"
            )));
        }
        channels.push(AnyChannel::new(
            name.as_str(),
            FlatSamples::F32(values.clone()),
        ));
    }
    if let SampleCounts::PerPixel(per_pixel) = counts {
        // Exact in u32 (f32 would round counts above 2^24).
        channels.push(AnyChannel::new(
            "samples.Y",
            FlatSamples::U32(per_pixel.to_vec()),
        ));
    }
    let channels = AnyChannels::sort(SmallVec::from_vec(channels));
    let mut image = Image::from_channels((width as usize, height as usize), channels);
    for (name, value) in metadata {
        let text = |t: &str| {
            exr::meta::attribute::Text::new_or_none(t).ok_or_else(|| {
                Error::Scene(format!(
                    "the EXR attribute {name} holds characters EXR cannot"
                ))
            })
        };
        (image.layer_data.attributes.other).insert(
            text(name)?,
            exr::meta::attribute::AttributeValue::Text(text(value)?),
        );
    }
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut out)
        .map_err(|e| Error::Scene(format!("encoding the EXR failed: {e}")))?;
    Ok(out.into_inner())
}

/// A render on a transparent film (`RenderSettings::transparent`) with its alpha, `coverage`:
/// EXR with the colour as rendered (premultiplied: the background added nothing) and an `A`
/// channel beside the variance and `extra` layers; PNG 8-bit RGBA with straight alpha (the colour
/// divided by alpha, then `view`), as Blender writes both. Other formats hold no alpha.
pub fn encode_with_alpha(
    format: ImageFormat,
    [width, height]: [u32; 2],
    pixels: &[[f32; 4]],
    counts: SampleCounts,
    coverage: &[f32],
    (extra, metadata): (&[ExrChannel], &[ExrAttribute]),
    view: impl Into<View>,
) -> Result<Vec<u8>> {
    if coverage.len() != pixels.len() {
        return Err(Error::Scene("the alpha does not match the image".into()));
    }
    match format {
        ImageFormat::Exr => {
            let mut layers = vec![("A".to_string(), coverage.to_vec())];
            layers.extend_from_slice(extra);
            encode_exr_layers(width, height, pixels, counts, &layers, metadata)
        }
        ImageFormat::Png => {
            let view = view.into();
            let mut rgba = Vec::with_capacity(pixels.len() * 4);
            for (p, &alpha) in pixels.iter().zip(coverage) {
                rgba.extend(view.straight_rgba8([p[0], p[1], p[2]], alpha));
            }
            let buffer = image::RgbaImage::from_raw(width, height, rgba)
                .ok_or_else(|| Error::Scene("image size does not match its pixels".into()))?;
            let mut out = std::io::Cursor::new(Vec::new());
            buffer
                .write_to(&mut out, image::ImageFormat::Png)
                .map_err(|e| Error::Scene(format!("encoding the PNG failed: {e}")))?;
            Ok(out.into_inner())
        }
        _ => Err(Error::Scene(
            "a transparent render needs an output with alpha: PNG or EXR".into(),
        )),
    }
}

/// Saves a render: EXR files get the variance channel beside the colour; other formats are
/// tone-mapped colour only.
pub fn save_render(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    counts: SampleCounts,
    view: impl Into<View>,
) -> Result<()> {
    let format = ImageFormat::from_path(path)?;
    let bytes = if format == ImageFormat::Exr {
        encode_exr_with_variance(width, height, pixels, counts)?
    } else {
        let rgb: Vec<[f32; 3]> = pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
        encode_image(format, width, height, &rgb, view)?
    };
    write_atomically(path, &bytes)
}

/// Saves an image atomically; the format follows the extension.
pub fn save_image(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    view: impl Into<View>,
) -> Result<()> {
    let format = ImageFormat::from_path(path)?;
    let bytes = encode_image(format, width, height, rgb, view)?;
    write_atomically(path, &bytes)
}

/// Writes `bytes` to a temporary file beside `path`, syncs it, and renames it over `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let io_err = |p: &Path| {
        let p: PathBuf = p.into();
        move |source| Error::Io { path: p, source }
    };
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("output");
    // The host as well as the process: render tasks on several machines may write one shared
    // directory (a retried or duplicated shard), and must neither share nor remove each other's.
    let tmp = dir.join(format!(
        ".{name}.{}-{}.tmp",
        host_name(),
        std::process::id()
    ));
    remove_stale_temporaries(dir, name);
    let result = (|| {
        let mut file = std::fs::File::create(&tmp).map_err(io_err(&tmp))?;
        file.write_all(bytes).map_err(io_err(&tmp))?;
        file.sync_all().map_err(io_err(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io_err(path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Removes `.NAME.PID.tmp` files that a killed save left behind: those of processes that no longer
/// run (on Linux, by `/proc`; elsewhere, those older than a day). Best effort: errors are ignored.
/// This machine's name as atomic saves put it in their temporary files' names.
pub fn host_name() -> String {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_default();
    let clean: String = name
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if clean.is_empty() {
        "host".into()
    } else {
        clean
    }
}

fn remove_stale_temporaries(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some((host, pid)) = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|rest| rest.strip_suffix(".tmp"))
            .and_then(|rest| rest.rsplit_once('-'))
            .and_then(|(host, pid)| Some((host.to_string(), pid.parse::<u32>().ok()?)))
        else {
            continue;
        };
        let here = host == host_name();
        if here && pid == std::process::id() {
            continue;
        }
        // Another machine's processes are not in this one's /proc: only age tells of those.
        let stale = if here && cfg!(target_os = "linux") {
            !Path::new(&format!("/proc/{pid}")).exists()
        } else {
            entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 24 * 3600)
        };
        if stale {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

#[cfg(test)]
mod tests;
