//! Encoded images decoded within the memory budget: PNG and JPEG (and float formats) into
//! [`Texture`]s, every pixel format widened to 16-bit RGBA; Radiance HDR and OpenEXR
//! latitude–longitude maps into linear float [`EnvironmentMap`]s.

use crate::limits::memory_budget;
use crate::scene::{EnvironmentMap, Texture, srgb_to_linear};

/// The image in `bytes` (format guessed from its first bytes) as a texture named `name`.
/// Grey images repeat their value in R, G and B (grey-alpha keeps its alpha); images
/// without alpha are opaque; float images are clamped to [0, 1]. The decoder refuses
/// images whose pixels would not fit in the memory budget, before allocating them.
pub fn decode_texture(name: String, bytes: &[u8]) -> Result<Texture, String> {
    let rgba = decode(bytes)?.to_rgba16();
    let (width, height) = rgba.dimensions();
    Ok(Texture {
        name,
        width,
        height,
        texels: rgba.pixels().map(|p| p.0).collect(),
    })
}

/// The latitude–longitude environment image in `bytes` (Radiance `.hdr`, OpenEXR, or any
/// format [`decode_texture`] reads, taken as sRGB) as linear RGB radiance named `name`.
/// Negative values (from image processing) become zero; a NaN or infinite value is an error.
pub fn decode_environment(name: String, bytes: &[u8]) -> Result<EnvironmentMap, String> {
    let decoded = decode(bytes)?;
    // Float images hold linear radiance; 8- and 16-bit ones are sRGB-encoded pictures.
    let linear = matches!(
        decoded.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let rgb = decoded.to_rgb32f();
    let (width, height) = rgb.dimensions();
    if width == 0 || height == 0 {
        return Err("is empty".into());
    }
    let mut texels = Vec::with_capacity(rgb.pixels().len());
    for p in rgb.pixels() {
        if !p.0.iter().all(|c| c.is_finite()) {
            return Err("holds NaN or infinite values".into());
        }
        texels.push(p.0.map(|c| {
            let c = c.max(0.0);
            if linear { c } else { srgb_to_linear(c) }
        }));
    }
    Ok(EnvironmentMap {
        name,
        width,
        height,
        texels,
    })
}

/// Decodes `bytes`, the format guessed from their first bytes, refusing images whose pixels
/// would not fit in the memory budget before allocating them.
fn decode(bytes: &[u8]) -> Result<image::DynamicImage, String> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot be decoded ({e})"))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(memory_budget());
    reader.limits(limits);
    reader
        .decode()
        .map_err(|e| format!("cannot be decoded ({e})"))
}
