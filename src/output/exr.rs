//! OpenEXR through the `exr` crate: linear 32-bit float RGBA, with the render record as a
//! text header attribute; and reading such files back for merging.

use std::collections::BTreeMap;
use std::path::Path;

use exr::meta::MetaData;
use exr::meta::attribute::{AttributeValue, Text, TextBytes};
use exr::prelude::*;
use glam::Vec3;

use crate::render::{AovImage, Image};

/// The image as EXR bytes: one part whose channels are the beauty (`R`, `G`, `B`, `A`) and
/// each auxiliary layer as `layer.channel` (OpenEXR's layer naming), with `text` — one
/// (name, value) attribute at most, since the `exr` crate writes several in hash-map order
/// and the bytes would change from run to run — in its header. Blocks are compressed in
/// parallel but written in increasing order (the crate writes them as they finish when
/// the order is unspecified), so the same image always gives the same bytes.
pub fn encode(image: &Image, text: Option<(&str, &str)>) -> std::result::Result<Vec<u8>, String> {
    let size = (image.width as usize, image.height as usize);
    let channels: Vec<AnyChannel<FlatSamples>> = channels_of(image)
        .into_iter()
        .map(|(name, samples)| AnyChannel::new(name.as_str(), FlatSamples::F32(samples)))
        .collect();
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::default()
    };
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(channels.into()),
    );
    let mut exr_image = exr::image::Image::from_layer(layer);
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

/// Every channel the image holds, by name, as row-major f32 samples.
fn channels_of(image: &Image) -> Vec<(String, Vec<f32>)> {
    let mut channels = Vec::new();
    let mut rgb = |layer: &str, names: [&str; 3], values: &[Vec3]| {
        for (c, name) in names.iter().enumerate() {
            let name = if layer.is_empty() {
                name.to_string()
            } else {
                format!("{layer}.{name}")
            };
            channels.push((name, values.iter().map(|p| p[c]).collect()));
        }
    };
    rgb("", ["R", "G", "B"], &image.pixels);
    let aovs = &image.aovs;
    if let Some(v) = &aovs.albedo {
        rgb("albedo", ["R", "G", "B"], v);
    }
    if let Some(v) = &aovs.normal {
        rgb("normal", ["X", "Y", "Z"], v);
    }
    if let Some(v) = &aovs.position {
        rgb("position", ["X", "Y", "Z"], v);
    }
    if let Some(v) = &aovs.variance {
        rgb("variance", ["R", "G", "B"], v);
    }
    if let Some((v, _)) = &aovs.noisy {
        rgb("noisy", ["R", "G", "B"], v);
    }
    channels.push(("A".into(), image.alpha.clone()));
    let single = [
        ("depth.Z", aovs.depth.clone()),
        ("coverage.A", aovs.coverage.clone()),
        ("noisy.A", aovs.noisy.as_ref().map(|(_, a)| a.clone())),
        (
            "samples.N",
            image
                .pixel_samples
                .as_ref()
                .map(|n| n.iter().map(|&n| n as f32).collect()),
        ),
    ];
    for (name, values) in single {
        if let Some(values) = values {
            channels.push((name.into(), values));
        }
    }
    channels
}

/// What an EXR's header says, read without its pixels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExrHeader {
    /// Width of the first layer in pixels.
    pub width: usize,
    /// Height of the first layer in pixels.
    pub height: usize,
    /// Channels of the first layer.
    pub channels: usize,
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
        channels: header.channels.list.len(),
        text,
    })
}

/// Text attribute bytes as UTF-8, with anything else replaced.
fn utf8(text: &Text) -> String {
    String::from_utf8_lossy(text.as_slice()).into_owned()
}

/// The pixels of an EXR gridtrace wrote: beauty, alpha, and every auxiliary layer present.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExrPixels {
    /// Radiance, row-major.
    pub rgb: Vec<Vec3>,
    /// Alpha.
    pub alpha: Vec<f32>,
    /// The auxiliary layers found.
    pub aovs: AovImage,
    /// Per-pixel sample counts (`samples.N`) of an adaptive render.
    pub pixel_samples: Option<Vec<u32>>,
}

/// Reads the first part's channels by name (`R`, `G`, `B`, `A` required; layers optional).
pub fn read_pixels(path: &Path) -> std::result::Result<ExrPixels, String> {
    let image = read_first_flat_layer_from_file(path).map_err(|e| e.to_string())?;
    let layer = image.layer_data;
    let n = layer.size.area();
    let channel = |name: &str| -> Option<Vec<f32>> {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.eq(name))
            .map(|c| match &c.sample_data {
                FlatSamples::F32(v) => v.clone(),
                FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
                FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
            })
            .filter(|v| v.len() == n)
    };
    let rgb = |layer: &str, names: [&str; 3]| -> Option<Vec<Vec3>> {
        let name = |c: &str| {
            if layer.is_empty() {
                c.to_string()
            } else {
                format!("{layer}.{c}")
            }
        };
        let [x, y, z] = names.map(|c| channel(&name(c)));
        Some(
            x?.into_iter()
                .zip(y?)
                .zip(z?)
                .map(|((x, y), z)| Vec3::new(x, y, z))
                .collect(),
        )
    };
    let beauty = rgb("", ["R", "G", "B"]).ok_or("no R, G and B channels")?;
    let alpha = channel("A").unwrap_or_else(|| vec![1.0; n]);
    let noisy = rgb("noisy", ["R", "G", "B"]).map(|v| (v, channel("noisy.A").unwrap_or_default()));
    let aovs = AovImage {
        albedo: rgb("albedo", ["R", "G", "B"]),
        normal: rgb("normal", ["X", "Y", "Z"]),
        depth: channel("depth.Z"),
        position: rgb("position", ["X", "Y", "Z"]),
        coverage: channel("coverage.A"),
        variance: rgb("variance", ["R", "G", "B"]),
        noisy,
    };
    let pixel_samples = channel("samples.N").map(|v| v.iter().map(|&s| s as u32).collect());
    Ok(ExrPixels {
        rgb: beauty,
        alpha,
        aovs,
        pixel_samples,
    })
}

/// Reads the beauty and alpha only: (radiance, alpha) row-major.
pub fn read_rgba(path: &Path) -> std::result::Result<(Vec<Vec3>, Vec<f32>), String> {
    read_pixels(path).map(|p| (p.rgb, p.alpha))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same image gives the same bytes, however its blocks' compression is scheduled:
    /// a render's output depends on its seed alone.
    #[test]
    fn the_same_image_encodes_to_the_same_bytes() {
        let mut image = Image::new(256, 256);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            // Blocks that compress to different sizes, so they finish at different times.
            let x = (i * 2_654_435_761) % 1000;
            *p = Vec3::new(
                x as f32 / 7.0,
                (i % 256) as f32,
                if i % 3 == 0 { 0.0 } else { 1.5 },
            );
        }
        let first = encode(&image, Some(("gridtrace/record", "seed=0"))).unwrap();
        for _ in 0..12 {
            assert!(encode(&image, Some(("gridtrace/record", "seed=0"))).unwrap() == first);
        }
    }
}
