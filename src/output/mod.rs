//! What a render becomes: images written atomically as OpenEXR (linear float) or PNG (8-bit
//! sRGB through a view transform); parts of one render merged ([`merge`]); an image denoised
//! ([`denoise`]); the image shown as it converges ([`display`]).

mod agx;
pub mod denoise;
pub mod display;
mod exr;
pub mod merge;
mod png;
pub mod temporary;

pub use exr::{
    ExrHeader, ExrPixels, read_header as read_exr_header, read_pixels as read_exr_pixels,
    read_rgba as read_exr_rgba,
};
pub use png::{ViewTransform, display_bytes};

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::record::{RECORD_ATTRIBUTE, RenderRecord};
use crate::render::Image;

/// An image file format gridtrace writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR, 32-bit float linear RGBA.
    Exr,
    /// PNG, 8-bit sRGB RGB through a [`ViewTransform`].
    Png,
}

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension names no format we write.
    #[error("{path}: unknown output format (use .exr or .png)")]
    UnknownFormat {
        /// The requested output path.
        path: PathBuf,
    },
    /// Encoding or file-system failure.
    #[error("{path}: {message}")]
    Write {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl Format {
    /// The format named by the file's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format, OutputError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") => Ok(Format::Exr),
            Some("png") => Ok(Format::Png),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Encodes `image` in the format of `path`'s extension and writes it atomically: the bytes
/// go to a temporary file in the same folder, which is renamed over `path` only when
/// complete, so an earlier image at `path` survives any failure.
pub fn write_image(path: &Path, image: &Image) -> Result<(), OutputError> {
    write_image_with_record(path, image, None, ViewTransform::Standard)
}

/// [`write_image`], with the render's record in an EXR's header or a PNG's text chunk (the
/// PNG's record also names its view transform, which an EXR does not apply).
pub fn write_image_with_record(
    path: &Path,
    image: &Image,
    record: Option<&RenderRecord>,
    view: ViewTransform,
) -> Result<(), OutputError> {
    let record = record.map(RenderRecord::to_text);
    let bytes = match Format::from_path(path)? {
        Format::Exr => exr::encode(image, record.as_deref().map(|r| (RECORD_ATTRIBUTE, r))),
        Format::Png => {
            let record = record.map(|r| format!("{r}viewTransform={}\n", view.name()));
            png::encode(
                image,
                view,
                record.as_deref().map(|r| (RECORD_ATTRIBUTE, r)),
            )
        }
    }
    .map_err(|message| OutputError::Write {
        path: path.to_path_buf(),
        message,
    })?;
    write_atomically(path, &bytes)
}

/// Checks before a long render (and before loading) that `path` has a known format, that
/// its folder accepts new files, and that an existing file there may be replaced (not a
/// directory, not immutable or read-only), so the render is not lost at the end.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    Format::from_path(path)?;
    let fail = |message: String| OutputError::Write {
        path: path.to_path_buf(),
        message,
    };
    match std::fs::metadata(path) {
        Ok(metadata) if metadata.is_dir() => {
            return Err(fail("is a directory; name an image file".into()));
        }
        Ok(metadata) if !metadata.is_file() => {
            return Err(fail("is not a regular file; name an image file".into()));
        }
        // An immutable (chattr +i) or read-only file refuses to be opened for writing;
        // opening without truncating leaves it as it is.
        Ok(_) => {
            if let Err(e) = std::fs::OpenOptions::new().write(true).open(path) {
                return Err(fail(format!("cannot replace the existing file: {e}")));
            }
        }
        Err(_) => {}
    }
    temporary::builder()
        .tempfile_in(parent_dir(path))
        .map(drop)
        .map_err(|e| fail(format!("cannot write here: {e}")))
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let fail = |e: std::io::Error| OutputError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut builder = temporary::builder();
    // Temporary files are private by default; an image should get the usual 0666 & !umask.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut file = builder.tempfile_in(parent_dir(path)).map_err(fail)?;
    file.write_all(bytes).map_err(fail)?;
    file.as_file().sync_all().map_err(fail)?;
    file.persist(path).map_err(|e| fail(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(
            Format::from_path(Path::new("a/b.EXR")).unwrap(),
            Format::Exr
        );
        assert_eq!(Format::from_path(Path::new("b.png")).unwrap(), Format::Png);
        assert!(Format::from_path(Path::new("b.jpg")).is_err());
        assert!(Format::from_path(Path::new("b")).is_err());
    }

    #[test]
    fn a_failed_write_keeps_the_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        let mut image = Image::new(2, 1);
        image.pixels[0] = Vec3::ONE;
        write_image(&path, &image).unwrap();
        let before = std::fs::read(&path).unwrap();
        // Writing to a path whose "folder" is a file fails; the earlier image is untouched.
        let bad = path.join("x.png");
        assert!(write_image(&bad, &image).is_err());
        assert_eq!(std::fs::read(&path).unwrap(), before);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary files left"
        );
    }

    #[cfg(unix)]
    #[test]
    fn images_are_readable_by_others_like_any_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.exr");
        write_image(&path, &Image::new(1, 1)).unwrap();
        let reference = dir.path().join("plain");
        std::fs::write(&reference, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&path), mode(&reference));
    }
}
