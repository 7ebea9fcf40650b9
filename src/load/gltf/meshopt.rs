//! `EXT_meshopt_compression` (and its ratified twin `KHR_meshopt_compression`): buffer
//! views whose bytes are stored compressed elsewhere, decoded into the place the view
//! describes, so everything downstream reads ordinary buffer views.
//!
//! The codecs and filters are meshoptimizer's own (`meshopt` crate, the reference C++
//! library), which its author documents as safe on untrusted input. A buffer marked
//! `fallback` with no `uri` holds no bytes of its own: it starts as zeros of its
//! `byteLength` and is filled by the views decoded into it.

use std::os::raw::c_void;

use meshopt::ffi;

/// The extension names, first the one glTF-Transform writes.
pub const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// The extension object on a glTF property, under either name.
fn extension<'a>(
    value: impl Fn(&str) -> Option<&'a gltf::json::Value>,
) -> Option<&'a gltf::json::Value> {
    EXTENSIONS.iter().find_map(|name| value(name))
}

/// True for a buffer that exists only as the target of decoded views.
pub(super) fn is_fallback(buffer: &gltf::Buffer) -> bool {
    extension(|n| buffer.extension_value(n)).is_some_and(|e| e["fallback"].as_bool() == Some(true))
}

/// Decodes every compressed buffer view into its buffer. A view that cannot be decoded
/// is an error, unless its buffer holds real bytes (not a `fallback` placeholder): then
/// those are used, with a warning pushed on `warnings`.
pub(super) fn decode_views(
    document: &gltf::Document,
    buffers: &mut [gltf::buffer::Data],
    warnings: &mut Vec<String>,
) -> Result<(), String> {
    for view in document.views() {
        if let Err(why) = decode_view(&view, buffers) {
            if is_fallback(&view.buffer()) || extension(|n| view.extension_value(n)).is_none() {
                return Err(why);
            }
            warnings.push(format!("{why}; using its uncompressed fallback"));
        }
    }
    Ok(())
}

/// Decodes one buffer view, if compressed, into its buffer.
fn decode_view(
    view: &gltf::buffer::View,
    buffers: &mut [gltf::buffer::Data],
) -> Result<(), String> {
    let Some(e) = extension(|n| view.extension_value(n)) else {
        return Ok(());
    };
    let what = |why: String| format!("buffer view {} (meshopt): {why}", view.index());
    let number = |key: &str| e[key].as_u64().map(|n| n as usize);
    let (Some(source), Some(length), Some(stride), Some(count)) = (
        number("buffer"),
        number("byteLength"),
        number("byteStride"),
        number("count"),
    ) else {
        return Err(what(
            "buffer, byteLength, byteStride and count are required".into(),
        ));
    };
    let offset = number("byteOffset").unwrap_or(0);
    let compressed = buffers
        .get(source)
        .and_then(|b| {
            offset
                .checked_add(length)
                .and_then(|end| b.0.get(offset..end))
        })
        .ok_or_else(|| {
            what(format!(
                "its compressed bytes are not inside buffer {source}"
            ))
        })?
        .to_vec();
    let mode = e["mode"].as_str().unwrap_or("");
    let filter = e["filter"].as_str().unwrap_or("NONE");
    let decoded_len = count
        .checked_mul(stride)
        .filter(|&n| n <= view.length())
        .ok_or_else(|| {
            what(format!(
                "{count} elements of {stride} bytes do not fit its {} bytes",
                view.length()
            ))
        })?;
    let decoded = decode(&compressed, mode, filter, count, stride).map_err(what)?;
    let target = buffers
        .get_mut(view.buffer().index())
        .and_then(|b| b.0.get_mut(view.offset()..view.offset() + decoded_len))
        .ok_or_else(|| what(format!("it runs past buffer {}", view.buffer().index())))?;
    target.copy_from_slice(&decoded[..decoded_len]);
    Ok(())
}

/// `count` elements of `stride` bytes from meshoptimizer's encoding `mode` then `filter`
/// (the extension's specification, §Modes and §Filters).
fn decode(
    compressed: &[u8],
    mode: &str,
    filter: &str,
    count: usize,
    stride: usize,
) -> Result<Vec<u8>, String> {
    let valid_stride = match mode {
        "ATTRIBUTES" => stride.is_multiple_of(4) && (4..=256).contains(&stride),
        "TRIANGLES" => (stride == 2 || stride == 4) && count.is_multiple_of(3),
        "INDICES" => stride == 2 || stride == 4,
        other => return Err(format!("unknown mode '{other}'")),
    };
    if !valid_stride {
        return Err(format!(
            "byteStride {stride} (or count {count}) is not allowed in mode {mode}"
        ));
    }
    crate::limits::check_memory(|| "a meshopt buffer view".into(), (count * stride) as u64)
        .map_err(|e| e.to_string())?;
    // Words, so the filters' 16- and 32-bit accesses are aligned.
    let mut words = vec![0u32; (count * stride).div_ceil(4)];
    let destination = words.as_mut_ptr().cast::<c_void>();
    // SAFETY: `words` holds at least count × stride bytes; the decoders write no more and
    // read no more than `compressed.len()` bytes from it.
    let status = unsafe {
        match mode {
            "ATTRIBUTES" => ffi::meshopt_decodeVertexBuffer(
                destination,
                count,
                stride,
                compressed.as_ptr(),
                compressed.len(),
            ),
            "TRIANGLES" => ffi::meshopt_decodeIndexBuffer(
                destination,
                count,
                stride,
                compressed.as_ptr(),
                compressed.len(),
            ),
            _ => ffi::meshopt_decodeIndexSequence(
                destination,
                count,
                stride,
                compressed.as_ptr(),
                compressed.len(),
            ),
        }
    };
    if status != 0 {
        return Err(format!(
            "the {mode} stream is corrupt (meshoptimizer error {status})"
        ));
    }
    let filter_ok = match (filter, stride) {
        ("NONE", _) => true,
        ("OCTAHEDRAL" | "COLOR", 4 | 8) | ("QUATERNION", 8) => mode == "ATTRIBUTES",
        ("EXPONENTIAL", _) => mode == "ATTRIBUTES",
        _ => false,
    };
    if !filter_ok {
        return Err(format!(
            "filter {filter} does not apply to {mode} with byteStride {stride}"
        ));
    }
    // SAFETY: as above; each filter rewrites `count` elements of `stride` bytes in place.
    unsafe {
        match filter {
            "OCTAHEDRAL" => ffi::meshopt_decodeFilterOct(destination, count, stride),
            "QUATERNION" => ffi::meshopt_decodeFilterQuat(destination, count, stride),
            "EXPONENTIAL" => ffi::meshopt_decodeFilterExp(destination, count, stride),
            "COLOR" => ffi::meshopt_decodeFilterColor(destination, count, stride),
            _ => {}
        }
    }
    Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_and_index_streams_round_trip() {
        let vertices: Vec<[f32; 3]> = (0..50).map(|i| [i as f32, 1.0, -(i as f32)]).collect();
        let encoded = meshopt::encode_vertex_buffer(&vertices).unwrap();
        let bytes = decode(&encoded, "ATTRIBUTES", "NONE", 50, 12).unwrap();
        assert_eq!(
            &bytes[..12],
            &[0.0f32, 1.0, -0.0].map(f32::to_le_bytes).concat()[..]
        );
        assert_eq!(&bytes[49 * 12..49 * 12 + 4], &49.0f32.to_le_bytes());
        let indices = [0u32, 1, 2, 2, 1, 3];
        let encoded = meshopt::encode_index_buffer(&indices, 4).unwrap();
        let bytes = decode(&encoded, "TRIANGLES", "NONE", 6, 4).unwrap();
        assert_eq!(bytes, indices.map(u32::to_le_bytes).concat());
    }

    #[test]
    fn corrupt_streams_and_bad_layouts_are_errors() {
        assert!(decode(&[0xa0, 1, 2, 3], "ATTRIBUTES", "NONE", 10, 12).is_err());
        assert!(decode(&[], "TRIANGLES", "NONE", 3, 4).is_err());
        assert!(decode(&[], "ATTRIBUTES", "NONE", 3, 6).is_err());
        assert!(decode(&[], "POINTS", "NONE", 3, 4).is_err());
    }
}
