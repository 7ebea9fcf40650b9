//! PNG output: the linear image through a view transform to 8-bit sRGB, with the render
//! record in an `iTXt` chunk.

use glam::DVec3;

use super::agx::Agx;
use crate::render::Image;
use crate::scene::linear_to_srgb;

/// How a PNG turns linear Rec.709 radiance into display values (EXR stays linear).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ViewTransform {
    /// The sRGB transfer curve alone: values above 1 clip.
    #[default]
    Standard,
    /// Blender's default since 4.0: a log-sigmoid image formation that rolls highlights off
    /// towards white (see `output/agx.rs`).
    Agx,
}

impl ViewTransform {
    /// The name on the command line and in records.
    pub fn name(self) -> &'static str {
        match self {
            ViewTransform::Standard => "standard",
            ViewTransform::Agx => "agx",
        }
    }
}

/// The 8-bit sRGB display values of `image` through `view`, row by row, RGB.
pub fn display_bytes(image: &Image, view: ViewTransform) -> Vec<u8> {
    let encode = |c: f32| (linear_to_srgb(c) * 255.0).round() as u8;
    match view {
        ViewTransform::Standard => image
            .pixels
            .iter()
            .flat_map(|p| p.to_array().map(encode))
            .collect(),
        ViewTransform::Agx => {
            let agx = Agx::new();
            image
                .pixels
                .iter()
                .flat_map(|p| {
                    let formed = agx.form(DVec3::from(p.as_dvec3().to_array()));
                    formed.to_array().map(|c| encode(c as f32))
                })
                .collect()
        }
    }
}

/// The image as PNG bytes, with `record` (if any) as an international text chunk.
pub fn encode(
    image: &Image,
    view: ViewTransform,
    record: Option<(&str, &str)>,
) -> Result<Vec<u8>, String> {
    let bytes = display_bytes(image, view);
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    if let Some((key, text)) = record {
        encoder
            .add_itxt_chunk(key.to_string(), text.to_string())
            .map_err(|e| e.to_string())?;
    }
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
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

    #[test]
    fn the_record_travels_in_the_png() {
        let mut image = Image::new(3, 2);
        image.pixels[4] = glam::Vec3::new(4.0, 0.5, 0.0);
        let bytes = encode(
            &image,
            ViewTransform::Agx,
            Some(("gridtrace/record", "seed=7\n")),
        )
        .unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let reader = decoder.read_info().unwrap();
        let chunk = &reader.info().utf8_text[0];
        assert_eq!(chunk.keyword, "gridtrace/record");
        assert_eq!(chunk.get_text().unwrap(), "seed=7\n");
    }
}
