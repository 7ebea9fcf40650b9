//! Decoded glTF images turned into [`Texture`]s: every pixel format widened to 16-bit RGBA.

use gltf::image::{Data, Format};

use crate::scene::Texture;

/// The image as a texture. Grey images repeat their value in R, G and B (and grey-alpha keeps
/// its alpha); images without alpha are opaque; float images are clamped to [0, 1].
pub fn texture_from_image(name: String, image: &Data) -> Texture {
    let (width, height) = (image.width, image.height);
    let pixels = &image.pixels;
    let count = width as usize * height as usize;
    let u8_at = |i: usize| u16::from(pixels[i]) * 257;
    let u16_at = |i: usize| u16::from_ne_bytes([pixels[2 * i], pixels[2 * i + 1]]);
    let f32_at = |i: usize| {
        let v = f32::from_ne_bytes([
            pixels[4 * i],
            pixels[4 * i + 1],
            pixels[4 * i + 2],
            pixels[4 * i + 3],
        ]);
        (v.clamp(0.0, 1.0) * 65535.0).round() as u16
    };
    let (channels, read): (usize, &dyn Fn(usize) -> u16) = match image.format {
        Format::R8 => (1, &u8_at),
        Format::R8G8 => (2, &u8_at),
        Format::R8G8B8 => (3, &u8_at),
        Format::R8G8B8A8 => (4, &u8_at),
        Format::R16 => (1, &u16_at),
        Format::R16G16 => (2, &u16_at),
        Format::R16G16B16 => (3, &u16_at),
        Format::R16G16B16A16 => (4, &u16_at),
        Format::R32G32B32FLOAT => (3, &f32_at),
        Format::R32G32B32A32FLOAT => (4, &f32_at),
    };
    let texels = (0..count)
        .map(|p| {
            let c = |k: usize| read(p * channels + k);
            match channels {
                1 => [c(0), c(0), c(0), u16::MAX],
                2 => [c(0), c(0), c(0), c(1)],
                3 => [c(0), c(1), c(2), u16::MAX],
                _ => [c(0), c(1), c(2), c(3)],
            }
        })
        .collect();
    Texture {
        name,
        width,
        height,
        texels,
    }
}
