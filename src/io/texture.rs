//! Textures: read encoded images (PNG or JPEG), check their header, convert to PNG on export.

use crate::error::{Error, Result};
use crate::io::Limits;
use crate::mesh::Texture;
use std::io::Cursor;
use std::sync::Arc;

/// Check encoded bytes (PNG or JPEG), read the pixel size from the header, enforce the limit.
pub fn from_bytes(origin: &str, bytes: Vec<u8>, limits: &Limits) -> Result<Texture> {
    let err = |m: String| Error::input(origin, m);
    let format = image::guess_format(&bytes)
        .map_err(|_| err("texture is not a recognised image (expected PNG or JPEG)".into()))?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(err(format!(
            "texture format {format:?} is not supported (PNG or JPEG only)"
        )));
    }
    let (width, height) = image::ImageReader::with_format(Cursor::new(&bytes), format)
        .into_dimensions()
        .map_err(|e| err(format!("corrupt texture image: {e}")))?;
    if width == 0 || height == 0 {
        return Err(err("texture image has zero size".into()));
    }
    if width as u64 * height as u64 > limits.max_texture_pixels {
        return Err(err(format!(
            "texture is {width}x{height} pixels, over the limit of {} pixels (--max-texture-pixels)",
            limits.max_texture_pixels
        )));
    }
    Ok(Texture {
        origin: origin.to_string(),
        bytes: Arc::new(bytes),
        width,
        height,
    })
}

/// Read a texture file.
pub fn from_file(path: &std::path::Path, limits: &Limits) -> Result<Texture> {
    let bytes = crate::io::read_file(path, limits)?;
    from_bytes(&path.display().to_string(), bytes, limits)
}

/// The texture as PNG bytes: PNG input is kept byte for byte, anything else is decoded and
/// re-encoded (MuJoCo loads PNG textures only).
pub fn to_png(tex: &Texture) -> Result<Vec<u8>> {
    if image::guess_format(&tex.bytes).ok() == Some(image::ImageFormat::Png) {
        return Ok(tex.bytes.as_ref().clone());
    }
    let img = image::load_from_memory(&tex.bytes)
        .map_err(|e| Error::input(&tex.origin, format!("corrupt texture image: {e}")))?;
    let mut out = Vec::new();
    img.write_to(&mut Cursor::new(&mut out), image::ImageFormat::Png)
        .map_err(|e| Error::input(&tex.origin, format!("cannot encode texture as PNG: {e}")))?;
    Ok(out)
}
