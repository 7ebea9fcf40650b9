//! OpenEXR output through the `exr` crate: linear 32-bit float RGBA.

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::*;

use crate::render::Image;

/// The image as EXR bytes.
pub fn encode(image: &Image) -> std::result::Result<Vec<u8>, String> {
    let width = image.width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = image.pixels[y * width + x];
        (p.x, p.y, p.z, image.alpha[y * width + x])
    });
    let mut exr_image = exr::image::Image::from_channels((width, image.height as usize), channels);
    // How many samples per pixel the image holds (fewer than asked if the render was stopped).
    exr_image
        .layer_data
        .attributes
        .other
        .insert(Text::from("spp"), AttributeValue::I32(image.spp as i32));
    let mut bytes = std::io::Cursor::new(Vec::new());
    exr_image
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}
