//! PNG output: the linear image through the sRGB transfer curve, 8 bits per channel.

use image::ImageEncoder;

use crate::render::Image;
use crate::scene::linear_to_srgb;

/// The image as PNG bytes.
pub fn encode(image: &Image) -> Result<Vec<u8>, String> {
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| {
            p.to_array()
                .map(|c| (linear_to_srgb(c) * 255.0).round() as u8)
        })
        .collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &bytes,
            image.width,
            image.height,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| e.to_string())?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_hits_its_anchor_points() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert!((linear_to_srgb(0.18) - 0.4613).abs() < 1e-3);
        assert!((linear_to_srgb(5.0) - 1.0).abs() < 1e-6);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
    }
}
