//! What a scene file may read: the file-access policy every loader goes through.
//!
//! A scene comes from anyone (a download, a render service, a shared farm), and the files it
//! names are read with the renderer's rights, so the policy is a whitelist of folders:
//!
//! - the folder of the scene file, and any folder named with `--asset-path` (the roots),
//!   compared after resolving `.`, `..` and symbolic links;
//! - regular files only: devices, FIFOs, sockets and directories are never opened (a FIFO
//!   or `/dev/zero` would block or never end);
//! - relative paths, absolute paths and `file:` URIs that land inside a root; anything else
//!   (another scheme, a path outside every root) is refused before the file system is
//!   asked about it, so a refusal says nothing about whether the file exists;
//! - at most a stated number of bytes from any file (a buffer's `byteLength`).
//!
//! Messages name the file that asked and the path it asked for, never the bytes read.

use std::fmt;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// The folders a scene may read from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AssetRoots {
    /// Canonical folders (no `..`, no symbolic links).
    roots: Vec<PathBuf>,
}

/// A file the policy refused, or could not read.
#[derive(Debug, thiserror::Error)]
pub enum AccessError {
    /// The path lands outside every root.
    #[error(
        "'{reference}' is outside the folders this scene may read ({roots}); refused (allow a folder with --asset-path)"
    )]
    Outside {
        /// The path as the scene wrote it.
        reference: String,
        /// The roots, for the message.
        roots: RootList,
    },
    /// Not a relative path, an absolute path or a `file:` URI.
    #[error("'{reference}' is not a file path (only files are read); refused")]
    Scheme {
        /// The path as the scene wrote it.
        reference: String,
    },
    /// A device, FIFO, socket or directory.
    #[error("'{reference}' is a {kind}, not a regular file; refused")]
    NotRegular {
        /// The path as the scene wrote it.
        reference: String,
        /// What it is.
        kind: &'static str,
    },
    /// No such file.
    #[error("'{reference}' not found ({})", looked.display())]
    Missing {
        /// The path as the scene wrote it.
        reference: String,
        /// Where it was looked for.
        looked: PathBuf,
    },
    /// The operating system's reason (no permission, ...).
    #[error("'{reference}': {source}")]
    Io {
        /// The path as the scene wrote it.
        reference: String,
        /// The reason.
        source: std::io::Error,
    },
}

impl AccessError {
    /// The same refusal naming the path as `reference` (as a layer wrote it, where the
    /// check was made on the path it resolved to).
    pub fn naming(mut self, name: &str) -> AccessError {
        match &mut self {
            AccessError::Outside { reference, .. }
            | AccessError::Scheme { reference }
            | AccessError::NotRegular { reference, .. }
            | AccessError::Missing { reference, .. }
            | AccessError::Io { reference, .. } => *reference = name.to_string(),
        }
        self
    }
}

/// Roots as a message lists them.
#[derive(Debug)]
pub struct RootList(Vec<PathBuf>);

impl fmt::Display for RootList {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<String> = self.0.iter().map(|r| r.display().to_string()).collect();
        f.write_str(&names.join(", "))
    }
}

impl AssetRoots {
    /// The scene file's folder (as named, and where a symbolic link to the file leads) and
    /// `extra` folders. Folders that do not exist are left out (nothing can be read there).
    pub fn for_scene(scene: &Path, extra: &[PathBuf]) -> AssetRoots {
        let folder = folder_of(scene).to_path_buf();
        let real_folder = scene
            .canonicalize()
            .ok()
            .and_then(|file| file.parent().map(Path::to_path_buf));
        let mut roots: Vec<PathBuf> = std::iter::once(folder)
            .chain(real_folder)
            .chain(extra.iter().cloned())
            .filter_map(|dir| dir.canonicalize().ok())
            .filter(|dir| dir.is_dir())
            .collect();
        roots.sort();
        roots.dedup();
        AssetRoots { roots }
    }

    /// The canonical root folders.
    pub fn roots(&self) -> &[PathBuf] {
        &self.roots
    }

    /// Where `reference` (a path relative to `base`, an absolute path, or a `file:` URI),
    /// leads, if the policy allows reading it: a canonical path to a regular file inside a
    /// root.
    pub fn resolve(&self, base: &Path, reference: &str) -> Result<PathBuf, AccessError> {
        let path = file_path(reference).ok_or_else(|| AccessError::Scheme {
            reference: reference.to_string(),
        })?;
        let joined = if path.is_absolute() {
            path
        } else {
            base.canonicalize()
                .unwrap_or_else(|_| absolute(base))
                .join(path)
        };
        // Lexically outside: refused without asking the file system anything.
        let lexical = normalize(&joined);
        if !self.contains(&lexical) {
            return Err(self.outside(reference));
        }
        let canonical = joined.canonicalize().map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                AccessError::Missing {
                    reference: reference.to_string(),
                    looked: lexical.clone(),
                }
            } else {
                AccessError::Io {
                    reference: reference.to_string(),
                    source,
                }
            }
        })?;
        // Inside by name, outside through a symbolic link.
        if !self.contains(&canonical) {
            return Err(self.outside(reference));
        }
        let metadata = std::fs::metadata(&canonical).map_err(|source| AccessError::Io {
            reference: reference.to_string(),
            source,
        })?;
        check_regular(&metadata, reference)?;
        Ok(canonical)
    }

    /// Resolves `reference` and reads at most `limit` bytes of it.
    pub fn read(&self, base: &Path, reference: &str, limit: u64) -> Result<Vec<u8>, AccessError> {
        let path = self.resolve(base, reference)?;
        read_regular_file(&path, reference, limit)
    }

    /// True if `path` (absolute, normalised) lies in a root.
    pub fn contains(&self, path: &Path) -> bool {
        self.roots.iter().any(|root| path.starts_with(root))
    }

    fn outside(&self, reference: &str) -> AccessError {
        AccessError::Outside {
            reference: reference.to_string(),
            roots: RootList(self.roots.clone()),
        }
    }
}

/// The folder a file lies in, `.` for a bare file name: where its relative paths start.
pub fn folder_of(file: &Path) -> &Path {
    match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Reads at most `limit` bytes of the regular file at `path`, refusing anything else even if
/// it was swapped in after the policy's check: the file is opened without blocking (a FIFO
/// would wait for a writer) and checked again once open.
pub fn read_regular_file(path: &Path, reference: &str, limit: u64) -> Result<Vec<u8>, AccessError> {
    let io = |source| AccessError::Io {
        reference: reference.to_string(),
        source,
    };
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY);
    }
    let file = options.open(path).map_err(io)?;
    let metadata = file.metadata().map_err(io)?;
    check_regular(&metadata, reference)?;
    let size = metadata.len().min(limit);
    crate::limits::check_memory(|| format!("'{reference}'"), size)
        .map_err(|e| io(std::io::Error::other(e.to_string())))?;
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(size as usize)
        .map_err(|e| io(std::io::Error::other(e)))?;
    file.take(limit).read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes)
}

/// Refuses a file named on the command line (a scene, a part to merge, an image to denoise)
/// that is not a regular file — a FIFO would make its reader wait for a writer forever —
/// without opening it. A path that cannot be looked at is left to the reader, whose message
/// says why.
pub fn check_named_file(path: &Path) -> Result<(), AccessError> {
    match std::fs::metadata(path) {
        Ok(metadata) => check_regular(&metadata, &path.display().to_string()),
        Err(_) => Ok(()),
    }
}

fn check_regular(metadata: &std::fs::Metadata, reference: &str) -> Result<(), AccessError> {
    let file_type = metadata.file_type();
    if file_type.is_file() {
        return Ok(());
    }
    let kind = if file_type.is_dir() {
        "directory"
    } else {
        special_kind(&file_type)
    };
    Err(AccessError::NotRegular {
        reference: reference.to_string(),
        kind,
    })
}

#[cfg(unix)]
fn special_kind(file_type: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if file_type.is_fifo() {
        "FIFO"
    } else if file_type.is_socket() {
        "socket"
    } else if file_type.is_block_device() || file_type.is_char_device() {
        "device"
    } else {
        "special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_file_type: &std::fs::FileType) -> &'static str {
    "special file"
}

/// A relative or absolute path, or a `file:` URI's path (`file:///x`, `file://localhost/x`,
/// `file:/x`); `None` for any other scheme (`http:`, `data:`, ...). A single letter before
/// the colon is a Windows drive, not a scheme, and stays a (relative, missing) path.
fn file_path(reference: &str) -> Option<PathBuf> {
    if let Some(rest) = strip_prefix_ignore_case(reference, "file:") {
        // An authority other than localhost names another machine.
        let local = match rest.strip_prefix("//") {
            Some(authority_and_path) => {
                authority_and_path.strip_prefix("localhost").or_else(|| {
                    authority_and_path
                        .starts_with('/')
                        .then_some(authority_and_path)
                })
            }
            None => Some(rest),
        };
        return local.filter(|p| p.starts_with('/')).map(PathBuf::from);
    }
    let scheme = reference.split_once(':').map(|(s, _)| s);
    let is_scheme = scheme.is_some_and(|s| {
        s.len() > 1
            && s.starts_with(|c: char| c.is_ascii_alphabetic())
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    (!is_scheme).then(|| PathBuf::from(reference))
}

fn strip_prefix_ignore_case<'a>(text: &'a str, prefix: &str) -> Option<&'a str> {
    // `get`: the text may hold a multi-byte character where the prefix would end (found by
    // fuzzing).
    text.get(..prefix.len())
        .filter(|head| head.eq_ignore_ascii_case(prefix))
        .map(|_| &text[prefix.len()..])
}

/// `path` made absolute against the working folder.
fn absolute(path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(path)
    }
}

/// `.` and `..` resolved by name (`..` at the root stays at the root).
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_dir() -> (tempfile::TempDir, AssetRoots) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("scene")).unwrap();
        std::fs::write(dir.path().join("scene/inside.bin"), b"inside").unwrap();
        std::fs::write(dir.path().join("secret"), b"secret").unwrap();
        let roots = AssetRoots::for_scene(&dir.path().join("scene/a.gltf"), &[]);
        (dir, roots)
    }

    #[test]
    fn files_inside_the_scene_folder_are_read() {
        let (dir, roots) = scene_dir();
        let base = dir.path().join("scene");
        assert_eq!(roots.read(&base, "inside.bin", 100).unwrap(), b"inside");
        assert_eq!(
            roots.read(&base, "./../scene/inside.bin", 3).unwrap(),
            b"ins"
        );
        let uri = format!("file://{}", base.join("inside.bin").display());
        assert_eq!(roots.read(&base, &uri, 100).unwrap(), b"inside");
    }

    #[test]
    fn paths_outside_the_roots_are_refused_without_their_content() {
        let (dir, roots) = scene_dir();
        let base = dir.path().join("scene");
        let absolute = dir.path().join("secret").display().to_string();
        for reference in [
            "../secret".to_string(),
            absolute.clone(),
            format!("file://{absolute}"),
            "/etc/passwd".into(),
            "/proc/self/environ".into(),
        ] {
            let error = roots.read(&base, &reference, 100).unwrap_err();
            assert!(
                matches!(error, AccessError::Outside { .. }),
                "{reference}: {error}"
            );
            assert!(!error.to_string().contains("secret\n"), "{error}");
        }
        assert!(matches!(
            roots.read(&base, "https://example.com/x.bin", 100),
            Err(AccessError::Scheme { .. })
        ));
        // A second root allows its files.
        let wider = AssetRoots::for_scene(&base.join("a.gltf"), &[dir.path().to_path_buf()]);
        assert_eq!(wider.read(&base, "../secret", 100).unwrap(), b"secret");
    }

    #[cfg(unix)]
    #[test]
    fn links_out_of_the_roots_and_special_files_are_refused() {
        let (dir, roots) = scene_dir();
        let base = dir.path().join("scene");
        std::os::unix::fs::symlink(dir.path().join("secret"), base.join("link.bin")).unwrap();
        assert!(matches!(
            roots.read(&base, "link.bin", 100),
            Err(AccessError::Outside { .. })
        ));
        let fifo = std::ffi::CString::new(base.join("pipe.bin").to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
        assert!(matches!(
            roots.read(&base, "pipe.bin", 100),
            Err(AccessError::NotRegular { kind: "FIFO", .. })
        ));
        assert!(matches!(
            roots.read(&base, ".", 100),
            Err(AccessError::NotRegular {
                kind: "directory",
                ..
            })
        ));
    }

    #[test]
    fn schemes_are_told_from_paths() {
        assert_eq!(file_path("a/b.bin"), Some(PathBuf::from("a/b.bin")));
        assert_eq!(file_path("C:\\x.png"), Some(PathBuf::from("C:\\x.png")));
        assert_eq!(file_path("FILE:///x"), Some(PathBuf::from("/x")));
        assert_eq!(file_path("file://localhost/x"), Some(PathBuf::from("/x")));
        assert_eq!(file_path("file://server/x"), None);
        assert_eq!(file_path("http://x"), None);
        assert_eq!(file_path("data:abc"), None);
        assert_eq!(
            file_path("data\u{2de}x"),
            Some(PathBuf::from("data\u{2de}x"))
        );
    }
}
