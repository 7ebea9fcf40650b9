//! Encoded images (PNG, JPEG) decoded into [`Texture`]s: every pixel format widened to
//! 16-bit RGBA, within the memory budget.

use crate::limits::memory_budget;
use crate::scene::Texture;

/// The image in `bytes` (format guessed from its first bytes) as a texture named `name`.
/// Grey images repeat their value in R, G and B (grey-alpha keeps its alpha); images
/// without alpha are opaque; float images are clamped to [0, 1]. The decoder refuses
/// images whose pixels would not fit in the memory budget, before allocating them.
pub fn decode_texture(name: String, bytes: &[u8]) -> Result<Texture, String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be decoded ({e})"))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(memory_budget());
    reader.limits(limits);
    let decoded = reader
        .decode()
        .map_err(|e| format!("cannot be decoded ({e})"))?;
    let rgba = decoded.to_rgba16();
    let (width, height) = rgba.dimensions();
    Ok(Texture {
        name,
        width,
        height,
        texels: rgba.pixels().map(|p| p.0).collect(),
    })
}
