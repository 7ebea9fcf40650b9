//! The bytes a glTF file points at — buffers and images in the GLB chunk, in data URIs or
//! in files beside it — read through the file-access policy ([`AssetRoots`]): a file
//! outside the roots, a device or a FIFO is refused, and a buffer reads at most its
//! `byteLength`.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use crate::limits::check_memory;
use crate::load::LoadError;
use crate::load::access::{AccessError, AssetRoots, folder_of};
use crate::record::Dependency;

/// The files of one glTF scene: where relative URIs start, what may be read, and what was.
pub(super) struct SceneFiles {
    /// The glTF file, named in messages.
    pub asker: PathBuf,
    /// Its folder, where relative URIs start.
    pub base: PathBuf,
    /// The folders it may read.
    pub roots: AssetRoots,
    /// The files resolved so far, for the render record.
    pub read: Vec<Dependency>,
}

impl SceneFiles {
    pub fn new(asker: &Path, roots: AssetRoots) -> SceneFiles {
        let base = folder_of(asker).to_path_buf();
        SceneFiles {
            asker: asker.to_path_buf(),
            base,
            roots,
            read: Vec::new(),
        }
    }

    /// The file a (percent-encoded, RFC 3986) URI names, if the policy allows it.
    pub fn resolve(&mut self, uri: &str) -> Result<PathBuf, AccessError> {
        let decoded = urlencoding::decode(uri).map_or_else(|_| uri.into(), |d| d.into_owned());
        let path = self.roots.resolve(&self.base, &decoded)?;
        if !self.read.iter().any(|d| d.path == path) {
            self.read.push(Dependency::whole(path.clone()));
        }
        Ok(path)
    }

    /// At most `limit` bytes of the file `uri` names (the whole file for `None`).
    pub fn read(&mut self, uri: &str, limit: Option<u64>) -> Result<Vec<u8>, AccessError> {
        let path = self.resolve(uri)?;
        if let Some(dependency) = self.read.iter_mut().find(|d| d.path == path) {
            dependency.bytes_read = limit;
        }
        crate::load::access::read_regular_file(&path, uri, limit.unwrap_or(u64::MAX))
    }
}

/// Every buffer's bytes, in buffer order: the GLB binary chunk, a base64 data URI, or a file
/// read through the policy, each holding at least its `byteLength` (glTF 2.0 §3.6.1), with
/// meshopt-compressed views decoded in place, and warnings about views whose uncompressed
/// fallback is used.
pub(super) fn read_buffers(
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    files: &mut SceneFiles,
) -> Result<(Vec<gltf::buffer::Data>, Vec<String>), LoadError> {
    let path = files.asker.clone();
    let invalid = |what: String| LoadError::Invalid {
        path: path.clone(),
        what,
    };
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let (index, length) = (buffer.index(), buffer.length());
        check_memory(|| format!("buffer {index}"), length as u64)
            .map_err(|e| invalid(e.to_string()))?;
        let (mut data, name) = match buffer.source() {
            // Filled by the compressed views decoded into it (EXT_meshopt_compression).
            gltf::buffer::Source::Bin if super::meshopt::is_fallback(&buffer) => {
                (vec![0; length], "its decoded views".to_string())
            }
            gltf::buffer::Source::Bin => (
                blob.take().ok_or_else(|| {
                    invalid(format!(
                        "buffer {index} is the GLB binary chunk, which the file does not have"
                    ))
                })?,
                "the GLB binary chunk".to_string(),
            ),
            gltf::buffer::Source::Uri(uri) if is_data_uri(uri) => (
                decode_data_uri(uri)
                    .map_err(|why| invalid(format!("buffer {index}: bad data URI: {why}")))?,
                "its data URI".to_string(),
            ),
            gltf::buffer::Source::Uri(uri) => (
                files
                    .read(uri, Some(length as u64))
                    .map_err(|e| invalid(format!("buffer {index}: {e}")))?,
                format!("'{uri}'"),
            ),
        };
        if data.len() < length {
            return Err(invalid(format!(
                "buffer {index}: {name} holds {} bytes, but its byteLength is {length}",
                data.len()
            )));
        }
        // Accessors are 4-byte aligned; pad as the gltf crate's own import does.
        while data.len() % 4 != 0 {
            data.push(0);
        }
        buffers.push(gltf::buffer::Data(data));
    }
    let mut warnings = Vec::new();
    super::meshopt::decode_views(document, &mut buffers, &mut warnings).map_err(invalid)?;
    let warnings = warnings
        .into_iter()
        .map(|w| format!("{}: {w}", path.display()))
        .collect();
    Ok((buffers, warnings))
}

/// An image's encoded bytes: a slice of a buffer view, a data URI, or a file read through
/// the policy (at most what the memory budget allows).
pub(super) fn image_bytes<'a>(
    image: &gltf::Image,
    buffers: &'a [gltf::buffer::Data],
    files: &mut SceneFiles,
) -> Result<Cow<'a, [u8]>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = buffers.get(view.buffer().index()).map_or(&[][..], |b| &b.0);
            let end = view.offset().checked_add(view.length());
            match end.filter(|&end| end <= buffer.len()) {
                Some(end) => Ok(Cow::Borrowed(&buffer[view.offset()..end])),
                None => Err(format!(
                    "buffer view {} runs past its buffer ({} bytes)",
                    view.index(),
                    buffer.len()
                )),
            }
        }
        gltf::image::Source::Uri { uri, .. } if is_data_uri(uri) => {
            decode_data_uri(uri).map(Cow::Owned)
        }
        gltf::image::Source::Uri { uri, .. } => files
            .read(uri, None)
            .map(Cow::Owned)
            .map_err(|e| e.to_string()),
    }
}

/// True for a `data:` URI (the scheme is case-insensitive, RFC 3986 §3.1).
pub(super) fn is_data_uri(uri: &str) -> bool {
    uri.get(..5)
        .is_some_and(|s| s.eq_ignore_ascii_case("data:"))
}

/// The bytes of a base64 `data:` URI (RFC 2397); glTF allows no other encoding.
fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let (_, data) = uri
        .split_once(";base64,")
        .ok_or("only base64 data URIs are allowed")?;
    base64::decode(data).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_decode_and_other_encodings_are_refused() {
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAEC").unwrap(),
            [0, 1, 2]
        );
        assert!(decode_data_uri("data:,hello").is_err());
        assert!(is_data_uri("DATA:x") && !is_data_uri("dat"));
    }
}
