//! Encoded images decoded within the memory budget: PNG, JPEG, WebP (and float formats),
//! and Basis Universal KTX2 (`KHR_texture_basisu`) into [`Texture`]s, every pixel format
//! widened to 16-bit RGBA; Radiance HDR and OpenEXR
//! latitude–longitude maps into linear float [`EnvironmentMap`]s.

use crate::limits::{Reservation, check_memory, reserve_memory};
use crate::load::guard::catching_panics;
use crate::scene::{EnvironmentMap, Texture, srgb_to_linear};

/// The image in `bytes` (format guessed from its first bytes) as a texture named `name`.
/// Grey images repeat their value in R, G and B (grey-alpha keeps its alpha); images
/// without alpha are opaque; float images are clamped to [0, 1]. The decoder refuses
/// images whose pixels would not fit in the memory budget, before allocating them.
pub fn decode_texture(name: String, bytes: &[u8]) -> Result<Texture, String> {
    if bytes.starts_with(KTX2_MAGIC) {
        return decode_basis(name, bytes);
    }
    let (decoded, _reserved) = decode(bytes, TEXTURE_BYTES_PER_TEXEL)?;
    let rgba = decoded.to_rgba16();
    drop(decoded);
    let (width, height) = rgba.dimensions();
    Ok(Texture {
        name,
        width,
        height,
        texels: rgba.pixels().map(|p| p.0).collect(),
        tiles: Vec::new(),
    })
}

/// Most bytes a texel takes on its way to a [`Texture`]: the decoder's output (at most
/// 32-bit float RGBA, 16 bytes), the 16-bit RGBA conversion (8) and the texels kept (8),
/// reserved together before decoding so no copy after the check can exceed the budget.
const TEXTURE_BYTES_PER_TEXEL: u64 = 16 + 8 + 8;

/// The same for an [`EnvironmentMap`]: the decoder's output (16), the float RGB
/// conversion (12) and the texels kept (12).
const ENVIRONMENT_BYTES_PER_TEXEL: u64 = 16 + 12 + 12;

/// The first bytes of every KTX 2.0 file (KTX 2.0 §3.1).
const KTX2_MAGIC: &[u8] = b"\xabKTX 20\xbb\r\n\x1a\n";

/// A Basis Universal KTX2 texture (ETC1S or UASTC, any supercompression): its first
/// level transcoded to 8-bit RGBA by `basisu`, a pure-Rust port of Binomial's reference
/// transcoder. The values stay as encoded (sRGB or linear), like a PNG's.
fn decode_basis(name: String, bytes: &[u8]) -> Result<Texture, String> {
    use basisu::{DecodeFlags, TargetFormat, Transcoder};
    let failed = |e: basisu::Error| format!("cannot be decoded as KTX2 ({e:?})");
    check_ktx2_header(bytes)?;
    let (width, height, rgba) = catching_panics(|| {
        let transcoder = Transcoder::new(bytes).map_err(failed)?;
        let (width, height) = transcoder.base_dimensions();
        let texels = u64::from(width) * u64::from(height);
        // The 8-bit transcode and our 16-bit copy of it.
        check_memory(|| name.clone(), texels.saturating_mul(4 + 8)).map_err(|e| e.to_string())?;
        let rgba = transcoder
            .transcode(0, TargetFormat::Rgba32, DecodeFlags::NONE)
            .map_err(failed)?;
        Ok::<_, String>((width, height, rgba))
    })
    .map_err(|why| format!("cannot be decoded as KTX2 (the transcoder failed: {why})"))??;
    let texels = u64::from(width) * u64::from(height);
    if width == 0 || height == 0 || rgba.len() as u64 != texels * 4 {
        return Err(format!(
            "holds a {width}×{height} image it does not deliver"
        ));
    }
    Ok(Texture {
        name,
        width,
        height,
        texels: rgba
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2], p[3]].map(|c| u16::from(c) * 257))
            .collect(),
        tiles: Vec::new(),
    })
}

/// Refuses a KTX2 file whose header claims an image larger than the memory budget allows,
/// or a Zstandard-supercompressed level longer than its image can hold (16 bytes per 4×4
/// block, UASTC's size, for every layer and face): the transcoder allocates both before
/// decoding (found by fuzzing). Fields from the KTX 2.0 header (§3) and level index (§3.9).
fn check_ktx2_header(bytes: &[u8]) -> Result<(), String> {
    let word = |at: usize| -> Option<u64> {
        let b = bytes.get(at..at + 4)?;
        Some(u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
    };
    let long = |at: usize| -> Option<u64> { Some(word(at)? | (word(at + 4)? << 32)) };
    let header = (|| {
        let (width, height) = (word(20)?, word(24)?.max(1));
        let (layers, faces, levels, scheme) = (
            word(32)?.max(1),
            word(36)?.max(1),
            word(40)?.max(1),
            word(44)?,
        );
        Some((width, height, layers, faces, levels, scheme))
    })();
    let Some((width, height, layers, faces, levels, scheme)) = header else {
        return Err("is a truncated KTX2 file".into());
    };
    // The transcoder allocates by the image's size before decoding anything; so do we
    // (its 8-bit output and our 16-bit copy).
    let texels = width
        .saturating_mul(height)
        .saturating_mul(layers)
        .saturating_mul(faces);
    check_memory(
        || format!("a {width}×{height} KTX2 image"),
        texels.saturating_mul(12),
    )
    .map_err(|e| e.to_string())?;
    const ZSTANDARD: u64 = 2;
    if scheme != ZSTANDARD {
        return Ok(());
    }
    let most = width
        .div_ceil(4)
        .saturating_mul(height.div_ceil(4))
        .saturating_mul(16)
        .saturating_mul(layers)
        .saturating_mul(faces);
    for level in 0..levels.min(32) as usize {
        let Some(uncompressed) = long(80 + 24 * level + 16) else {
            return Err("is a truncated KTX2 file".into());
        };
        if uncompressed > most {
            return Err(format!(
                "cannot be decoded as KTX2 (level {level} claims {uncompressed} bytes for a {width}×{height} image)"
            ));
        }
        check_memory(|| format!("KTX2 level {level}"), uncompressed).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// The latitude–longitude environment image in `bytes` (Radiance `.hdr`, OpenEXR, or any
/// format [`decode_texture`] reads, taken as sRGB) as linear RGB radiance named `name`.
/// Negative values (from image processing) become zero; a NaN or infinite value is an error.
pub fn decode_environment(name: String, bytes: &[u8]) -> Result<EnvironmentMap, String> {
    let (decoded, _reserved) = decode(bytes, ENVIRONMENT_BYTES_PER_TEXEL)?;
    // Float images hold linear radiance; 8- and 16-bit ones are sRGB-encoded pictures.
    let linear = matches!(
        decoded.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let rgb = decoded.to_rgb32f();
    drop(decoded);
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

/// Decodes `bytes`, the format guessed from their first bytes. The header's size is read
/// first and `bytes_per_texel` for every pixel reserved from the budget (the decode and the
/// caller's copies of it), so an image too large for memory is refused before anything is
/// allocated; the decoder itself is held to the reservation by `image`'s limits.
fn decode(
    bytes: &[u8],
    bytes_per_texel: u64,
) -> Result<(image::DynamicImage, Reservation), String> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot be decoded ({e})"))
    };
    let (width, height) = catching_panics(|| {
        reader()?
            .into_dimensions()
            .map_err(|e| format!("cannot be decoded ({e})"))
    })
    .map_err(|why| format!("cannot be decoded (the decoder failed: {why})"))??;
    let texels = u64::from(width) * u64::from(height);
    let reserved = reserve_memory(
        || format!("decoding its {width}x{height} pixels"),
        texels.saturating_mul(bytes_per_texel),
    )
    .map_err(|e| format!("is too large: {e}"))?;
    let mut reader = reader()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    limits.max_alloc = Some(reserved.bytes());
    reader.limits(limits);
    let decoded = catching_panics(|| reader.decode())
        .map_err(|why| format!("cannot be decoded (the decoder failed: {why})"))?
        .map_err(|e| format!("cannot be decoded ({e})"))?;
    Ok((decoded, reserved))
}
