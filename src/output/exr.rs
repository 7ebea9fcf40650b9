//! OpenEXR through the `exr` crate: linear 32-bit float RGBA, with the render record as a
//! text header attribute; and reading such files back for merging.

use std::collections::BTreeMap;
use std::path::Path;

use exr::meta::MetaData;
use exr::meta::attribute::{AttributeValue, Text, TextBytes};
use exr::prelude::*;
use glam::Vec3;

use crate::render::Image;

/// The image as EXR bytes, with `text` — one (name, value) attribute at most, since the
/// `exr` crate writes several in hash-map order and the bytes would change from run to
/// run — in its header.
pub fn encode(image: &Image, text: Option<(&str, &str)>) -> std::result::Result<Vec<u8>, String> {
    let width = image.width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = image.pixels[y * width + x];
        (p.x, p.y, p.z, image.alpha[y * width + x])
    });
    let mut exr_image = exr::image::Image::from_channels((width, image.height as usize), channels);
    // How many samples per pixel the image holds (fewer than asked if the render was
    // stopped): the only attribute of the layer's own map.
    exr_image
        .layer_data
        .attributes
        .other
        .insert(Text::from("spp"), AttributeValue::I32(image.spp as i32));
    // OpenEXR text attributes hold UTF-8 (names of cameras and files may be any script).
    let utf8 = |s: &str| Text::from_bytes_unchecked(TextBytes::from_slice(s.as_bytes()));
    if let Some((name, value)) = text {
        exr_image
            .attributes
            .other
            .insert(utf8(name), AttributeValue::Text(utf8(value)));
    }
    let mut bytes = std::io::Cursor::new(Vec::new());
    exr_image
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

/// What an EXR's header says, read without its pixels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExrHeader {
    /// Width of the first layer in pixels.
    pub width: usize,
    /// Height of the first layer in pixels.
    pub height: usize,
    /// The text attributes of the header, by name.
    pub text: BTreeMap<String, String>,
}

/// Reads the first layer's header.
pub fn read_header(path: &Path) -> std::result::Result<ExrHeader, String> {
    let meta = MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta.headers.first().ok_or("the file has no layers")?;
    let text = header
        .shared_attributes
        .other
        .iter()
        .chain(&header.own_attributes.other)
        .filter_map(|(name, value)| match value {
            AttributeValue::Text(text) => Some((utf8(name), utf8(text))),
            _ => None,
        })
        .collect();
    Ok(ExrHeader {
        width: header.layer_size.width(),
        height: header.layer_size.height(),
        text,
    })
}

/// Text attribute bytes as UTF-8, with anything else replaced.
fn utf8(text: &Text) -> String {
    String::from_utf8_lossy(text.as_slice()).into_owned()
}

/// Reads the first RGBA layer's pixels: (radiance, alpha) row-major.
pub fn read_rgba(path: &Path) -> std::result::Result<(Vec<Vec3>, Vec<f32>), String> {
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| {
            let n = size.width() * size.height();
            (size.width(), vec![Vec3::ZERO; n], vec![0.0f32; n])
        },
        |(width, rgb, alpha): &mut (usize, Vec<Vec3>, Vec<f32>),
         position,
         (r, g, b, a): (f32, f32, f32, f32)| {
            let i = position.y() * *width + position.x();
            rgb[i] = Vec3::new(r, g, b);
            alpha[i] = a;
        },
    )
    .map_err(|e| e.to_string())?;
    let (_, rgb, alpha) = image.layer_data.channel_data.pixels;
    Ok((rgb, alpha))
}
