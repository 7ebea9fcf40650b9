//! Merging parts of one render: EXR images of the same scene and settings that hold disjoint
//! sample ranges (`gridtrace SCENE --samples A..B`) combine into the image one process
//! rendering all their samples would have made.
//!
//! Every sample's random numbers depend on (seed, pixel, sample index) alone, so a part
//! holds exactly the samples a single render would have taken; each part stores per pixel
//! the f32 mean of its samples, and the merge weights the means by their sample counts in
//! f64. Radiance is never negative, so the only difference from one render is the f32
//! rounding of each part's mean and of the result: a merged pixel is within a relative
//! [`MERGE_TOLERANCE`] of the single render's (4 units of 2^-24, about two units in the last
//! place), and bit-identical for one part. Alpha (hit counts) merges exactly.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::limits::check_memory;
use crate::output::{read_exr_header, read_exr_pixels};
use crate::record::{RECORD_ATTRIBUTE, RecordError, RenderRecord, format_range};
use crate::render::aov::FeatureAccumulator;
use crate::render::{AovImage, Film, Image, PixelAccumulator};

/// Largest relative difference between a merged pixel and the single render's: 2^-22.
pub const MERGE_TOLERANCE: f32 = 1.0 / (1u32 << 22) as f32;

/// Parts bigger than this are refused before their pixels are read (a damaged header could
/// otherwise ask for any amount of memory).
const MAX_PART_PIXELS: usize = 1 << 28;

/// Most a part's pixel data can be compressed: no lossless OpenEXR compression packs more
/// than deflate's 1032:1 (ZIP; RLE reaches 64:1, PIZ's Huffman runs about 450:1), so a
/// header whose pixels would need more than this many times the file's size is damaged.
const MAX_COMPRESSION_RATIO: u64 = 2048;

/// Bytes of one f32 channel per pixel.
const CHANNEL_BYTES: u64 = 4;

/// Most channels a part may have: gridtrace writes at most 23 (the beauty's four and every
/// layer's).
const MAX_PART_CHANNELS: usize = 32;

/// Memory a merge holds per pixel: the accumulators, one part's pixels and the result,
/// with all their layers.
const MERGE_BYTES_PER_PIXEL: u64 = std::mem::size_of::<PixelAccumulator>() as u64
    + std::mem::size_of::<FeatureAccumulator>() as u64
    + 2 * 4 * 21;

/// One rendered part as its header describes it; the pixels are read when needed
/// ([`Part::read_image`]), so a merge holds one part's pixels at a time.
#[derive(Clone, Debug)]
pub struct Part {
    /// Where it was read from, for messages.
    pub path: PathBuf,
    /// What rendered it and which samples it holds.
    pub record: RenderRecord,
}

/// Why parts cannot be merged. Every message names the files concerned.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// Nothing to merge.
    #[error("no parts to merge")]
    NoParts,
    /// The file is not a readable EXR.
    #[error("{}: cannot read it as OpenEXR: {message}", path.display())]
    Unreadable {
        /// The part.
        path: PathBuf,
        /// What the EXR reader said.
        message: String,
    },
    /// The EXR has no render record.
    #[error("{}: not a gridtrace render: {source}", path.display())]
    NotAPart {
        /// The part.
        path: PathBuf,
        /// What is missing from its header.
        source: RecordError,
    },
    /// The pixels do not match the record, or hold values no render makes.
    #[error("{}: {message}; the file is damaged or was edited", path.display())]
    Damaged {
        /// The part.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The merge would need more memory than the run may use.
    #[error("{0}")]
    Memory(crate::limits::OverBudget),
    /// Two parts come from different renders.
    #[error(
        "{} and {} are not parts of one render: their {field} differs ('{ours}' and '{theirs}')",
        first.display(), other.display()
    )]
    Mismatch {
        /// The first part.
        first: PathBuf,
        /// The part that differs from it.
        other: PathBuf,
        /// The record field that differs.
        field: &'static str,
        /// The first part's value.
        ours: String,
        /// The other part's value.
        theirs: String,
    },
    /// Two parts share samples.
    #[error(
        "{} (samples {}) and {} (samples {}) overlap: samples {} would be counted twice",
        first.display(), Samples(first_samples), second.display(), Samples(second_samples),
        Samples(overlap)
    )]
    Overlap {
        /// One part.
        first: PathBuf,
        /// Its samples.
        first_samples: Range<u32>,
        /// The other part.
        second: PathBuf,
        /// Its samples.
        second_samples: Range<u32>,
        /// The samples both hold.
        overlap: Range<u32>,
    },
    /// An adaptive render's pixels hold different sample counts: not a part.
    #[error(
        "{}: rendered with --noise-threshold, so its pixels hold different numbers of samples \
         and it cannot be merged (split renders use a fixed --spp)",
        path.display()
    )]
    Adaptive {
        /// The part.
        path: PathBuf,
    },
    /// The parts leave samples out between them.
    #[error(
        "no part holds samples {} (between {} and {}): render them with --samples {}",
        Samples(missing), before.display(), after.display(), Samples(missing)
    )]
    Gap {
        /// The samples no part holds.
        missing: Range<u32>,
        /// The part that ends before them.
        before: PathBuf,
        /// The part that starts after them.
        after: PathBuf,
    },
    /// The parts do not cover the range asked for.
    #[error(
        "the parts hold samples {}, but {} were asked for",
        Samples(have),
        Samples(wanted)
    )]
    Incomplete {
        /// What the parts hold together.
        have: Range<u32>,
        /// What was asked for.
        wanted: Range<u32>,
    },
}

/// A sample range as `A..B` in messages.
struct Samples<'a>(&'a Range<u32>);

impl fmt::Display for Samples<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&format_range(self.0))
    }
}

/// Reads one part's header: its record, checked against the image size.
pub fn read_part(path: &Path) -> Result<Part, MergeError> {
    let part = |record| Part {
        path: path.to_path_buf(),
        record,
    };
    let header = read_exr_header(path).map_err(|message| MergeError::Unreadable {
        path: path.to_path_buf(),
        message,
    })?;
    let record = header
        .text
        .get(RECORD_ATTRIBUTE)
        .ok_or(RecordError::NoRecord)
        .and_then(|text| RenderRecord::from_text(text))
        .map_err(|source| MergeError::NotAPart {
            path: path.to_path_buf(),
            source,
        })?;
    let (width, height) = (record.identity.width, record.identity.height);
    if (header.width, header.height) != (width as usize, height as usize) {
        return Err(part(record).damaged(format!(
            "the record says {width}x{height} pixels but the image is {}x{}",
            header.width, header.height
        )));
    }
    let pixels = header.width.saturating_mul(header.height);
    if pixels > MAX_PART_PIXELS {
        return Err(part(record).damaged(format!(
            "{width}x{height} is more pixels than gridtrace renders by default"
        )));
    }
    if header.channels > MAX_PART_CHANNELS {
        return Err(part(record).damaged(format!(
            "it has {} channels; gridtrace writes at most {MAX_PART_CHANNELS}",
            header.channels
        )));
    }
    let file_size = std::fs::metadata(path).map_or(0, |m| m.len());
    let bytes = (pixels as u64).saturating_mul(CHANNEL_BYTES * header.channels.max(4) as u64);
    if bytes > file_size.saturating_mul(MAX_COMPRESSION_RATIO) {
        return Err(part(record).damaged(format!(
            "the header says {width}x{height} pixels, more than its {file_size} bytes can hold"
        )));
    }
    Ok(part(record))
}

impl Part {
    /// Reads the pixels: the mean radiance and alpha of the part's samples, checked to be
    /// values a render makes.
    pub fn read_image(&self) -> Result<Image, MergeError> {
        let read = read_exr_pixels(&self.path).map_err(|message| MergeError::Unreadable {
            path: self.path.clone(),
            message,
        })?;
        let mut aovs = read.aovs;
        // A denoised part merges by the samples it holds: its noisy beauty.
        let (pixels, alpha) = aovs.noisy.take().unwrap_or((read.rgb, read.alpha));
        let (width, height) = (self.record.identity.width, self.record.identity.height);
        let n = width as usize * height as usize;
        if pixels.len() != n || alpha.len() != n {
            return Err(self.damaged(format!(
                "{} pixels where the header says {width}x{height}",
                pixels.len()
            )));
        }
        let bad_pixel = pixels
            .iter()
            .zip(&alpha)
            .position(|(p, a)| !is_rendered_value(*p, *a));
        if let Some(i) = bad_pixel {
            return Err(self.damaged(format!(
                "pixel ({}, {}) holds {:?} alpha {}, which no render makes",
                i % width as usize,
                i / width as usize,
                pixels[i],
                alpha[i]
            )));
        }
        if aovs.set().label() != self.record.identity.aovs {
            return Err(self.damaged(format!(
                "its layers are '{}' but its record says '{}'",
                aovs.set().label(),
                self.record.identity.aovs
            )));
        }
        if let Some(i) = (0..n).find(|&i| !is_feature_value(&aovs, i)) {
            return Err(self.damaged(format!(
                "pixel ({}, {}) of a layer holds {:?}, which no render makes",
                i % width as usize,
                i / width as usize,
                aovs.pixel(i)
            )));
        }
        let samples = &self.record.samples;
        Ok(Image {
            width,
            height,
            pixels,
            alpha,
            spp: samples.end - samples.start,
            first_sample: samples.start,
            aovs,
            pixel_samples: read.pixel_samples,
        })
    }

    fn damaged(&self, message: String) -> MergeError {
        MergeError::Damaged {
            path: self.path.clone(),
            message,
        }
    }
}

/// Radiance is finite and never negative; alpha is a fraction.
fn is_rendered_value(radiance: Vec3, alpha: f32) -> bool {
    radiance.is_finite() && radiance.min_element() >= 0.0 && (0.0..=1.0).contains(&alpha)
}

/// Layer values are finite, coverage a fraction, variance never negative.
fn is_feature_value(aovs: &AovImage, i: usize) -> bool {
    let p = aovs.pixel(i);
    let finite = [p.albedo, p.normal, p.position, p.variance]
        .iter()
        .all(|v| v.is_finite())
        && p.depth.is_finite();
    finite && (0.0..=1.0).contains(&p.coverage) && p.variance.min_element() >= 0.0
}

/// Reads the parts at `paths`, checks that they belong to one render and hold disjoint,
/// contiguous sample ranges (covering `wanted` if given), and combines them: the merged
/// image and its record. Every header is checked before any pixels are read; the result
/// does not depend on the order of `paths`.
pub fn merge_files(
    paths: &[PathBuf],
    wanted: Option<Range<u32>>,
) -> Result<(Image, RenderRecord), MergeError> {
    let parts = paths
        .iter()
        .map(|p| read_part(p))
        .collect::<Result<Vec<_>, _>>()?;
    merge_parts(&parts, wanted)
}

/// [`merge_files`] for parts whose headers are read.
pub fn merge_parts(
    parts: &[Part],
    wanted: Option<Range<u32>>,
) -> Result<(Image, RenderRecord), MergeError> {
    let first = parts.first().ok_or(MergeError::NoParts)?;
    if let Some(adaptive) = parts.iter().find(|p| p.record.noise_threshold.is_some()) {
        return Err(MergeError::Adaptive {
            path: adaptive.path.clone(),
        });
    }
    for part in &parts[1..] {
        if let Some((field, ours, theirs)) = first.record.identity.difference(&part.record.identity)
        {
            return Err(MergeError::Mismatch {
                first: first.path.clone(),
                other: part.path.clone(),
                field,
                ours,
                theirs,
            });
        }
    }
    let mut order: Vec<&Part> = parts.iter().collect();
    order.sort_by_key(|p| (p.record.samples.start, p.record.samples.end));
    for pair in order.windows(2) {
        let (a, b) = (&pair[0].record.samples, &pair[1].record.samples);
        if b.start < a.end {
            return Err(MergeError::Overlap {
                first: pair[0].path.clone(),
                first_samples: a.clone(),
                second: pair[1].path.clone(),
                second_samples: b.clone(),
                overlap: b.start..a.end.min(b.end),
            });
        }
        if b.start > a.end {
            return Err(MergeError::Gap {
                missing: a.end..b.start,
                before: pair[0].path.clone(),
                after: pair[1].path.clone(),
            });
        }
    }
    let have = order[0].record.samples.start..order[order.len() - 1].record.samples.end;
    if let Some(wanted) = wanted
        && wanted != have
    {
        return Err(MergeError::Incomplete { have, wanted });
    }

    let identity = &first.record.identity;
    let (width, height) = (identity.width, identity.height);
    check_memory(
        || format!("merging {width}x{height} parts"),
        (width as u64 * height as u64).saturating_mul(MERGE_BYTES_PER_PIXEL),
    )
    .map_err(MergeError::Memory)?;
    let n = width as usize * height as usize;
    let mut pixels = vec![PixelAccumulator::default(); n];
    let mut features = Vec::new();
    let mut layers = None;
    for part in &order {
        let image = part.read_image()?;
        let set = image.aovs.set();
        if set.any() && features.is_empty() {
            features = vec![FeatureAccumulator::default(); n];
        }
        layers = Some(set);
        for (i, acc) in pixels.iter_mut().enumerate() {
            let from = PixelAccumulator::from_mean(image.pixels[i], image.alpha[i], image.spp);
            acc.merge(&from);
            if let Some(f) = features.get_mut(i) {
                let aov = image.aovs.pixel(i);
                f.merge(&FeatureAccumulator::from_means(
                    &aov,
                    image.pixels[i],
                    image.spp,
                ));
            }
        }
    }
    let film = Film::from_sums(
        width,
        height,
        have.start,
        layers.unwrap_or_default(),
        pixels,
        features,
    );
    let (image, _) = film.resolve(have.end - have.start);
    let record = RenderRecord {
        identity: identity.clone(),
        scene_name: first.record.scene_name.clone(),
        samples: have,
        nonfinite: parts.iter().map(|p| p.record.nonfinite).sum(),
        noise_threshold: None,
        denoised: false,
    };
    Ok((image, record))
}
