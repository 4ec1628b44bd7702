//! Loading image textures through `image` (and KTX2/Basis Universal through `basisu`), by content (by extension for TGA, which has no
//! signature): PNG, JPEG, TGA, BMP, TIFF, WebP, GIF, DDS,
//! QOI, PNM, HDR and EXR.

use std::path::Path;

use rt_core::error::{Error, Result};
use rt_core::scene::Texture;

/// Largest texture side accepted; bigger images are most likely corrupt headers.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

pub fn load_texture(path: &Path) -> Result<Texture> {
    let file_error = |message: String| Error::File {
        path: path.to_path_buf(),
        message,
    };
    if path.is_dir() {
        return Err(file_error("is a directory, not an image".into()));
    }
    let mut magic = [0u8; 12];
    let head = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read(&mut f, &mut magic))
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if is_ktx2(&magic[..head]) {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let rgba = transcode_basis(&bytes).map_err(file_error)?;
        return Ok(Texture {
            sampler: Default::default(),
            name: path.display().to_string(),
            width: rgba.width(),
            height: rgba.height(),
            rgba8: rgba.into_raw().into(),
        });
    }
    let reader = image::ImageReader::open(path)
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?
        .with_guessed_format()
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    let (width, height) = reader
        .into_dimensions()
        .map_err(|e| file_error(format!("unreadable image: {e}")))?;
    if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(file_error(format!(
            "texture is {width}x{height}; the limit is {MAX_TEXTURE_SIDE} per side"
        )));
    }
    let image = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?
        .decode()
        .map_err(|e| file_error(format!("unreadable image: {e}")))?;
    let rgba = image.to_rgba8();
    Ok(Texture {
        sampler: Default::default(),
        name: path.display().to_string(),
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw().into(),
    })
}

/// The signature a KTX2 file starts with.
const KTX2_MAGIC: [u8; 12] = [
    0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, b'\r', b'\n', 0x1A, b'\n',
];

/// A KTX2 container (glTF's `KHR_texture_basisu` images are).
pub fn is_ktx2(bytes: &[u8]) -> bool {
    bytes.starts_with(&KTX2_MAGIC)
}

/// A KTX2 texture in Basis Universal (ETC1S or UASTC), its first level transcoded to RGBA8 by
/// the pure-Rust `basisu` transcoder; other KTX2 payloads (raw or block-compressed formats) are
/// an error saying so.
pub fn transcode_basis(bytes: &[u8]) -> std::result::Result<image::RgbaImage, String> {
    // The transcoder is another crate's: a panic in it on a damaged file is an error here.
    std::panic::catch_unwind(|| transcode_unguarded(bytes)).unwrap_or_else(|_| {
        Err("the Basis Universal transcoder failed on this file (malformed input)".into())
    })
}

fn transcode_unguarded(bytes: &[u8]) -> std::result::Result<image::RgbaImage, String> {
    use basisu::{DecodeFlags, TargetFormat, Transcoder};
    let transcoder = Transcoder::new(bytes)
        .map_err(|e| format!("a KTX2 texture rt cannot read (Basis Universal only): {e:?}"))?;
    let (width, height) = transcoder.base_dimensions();
    if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE || width == 0 || height == 0 {
        return Err(format!(
            "texture is {width}x{height}; the limit is {MAX_TEXTURE_SIDE} per side"
        ));
    }
    // The transcoder is another crate's: a panic in it on a damaged file is an error here.
    let rgba = std::panic::catch_unwind(|| {
        transcoder.transcode(0, TargetFormat::Rgba32, DecodeFlags::NONE)
    })
    .map_err(|_| {
        "the Basis Universal transcoder failed on this file (malformed input)".to_string()
    })?
    .map_err(|e| format!("the Basis Universal texture does not transcode: {e:?}"))?;
    image::RgbaImage::from_raw(width, height, rgba)
        .ok_or_else(|| "the transcoded texture has the wrong size".to_string())
}
