//! Loading image textures through `image`, by content (by extension for TGA, which has no
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
