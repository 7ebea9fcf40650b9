//! Why a scene could not be loaded. Every message names the file.

use std::path::PathBuf;

/// A scene that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The scene file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The extension names no format we read.
    #[error(
        "{path}: unknown scene format (expected .gltf, .glb, .usd, .usda, .usdc, .usdz, .ply or .ply.gz)"
    )]
    UnknownFormat {
        /// The scene file.
        path: PathBuf,
    },
    /// The file is not valid glTF.
    #[error("{path}: invalid glTF: {message}")]
    Gltf {
        /// The scene file.
        path: PathBuf,
        /// What is wrong, with the JSON path where known.
        message: String,
    },
    /// The file requires extensions we do not implement.
    #[error("{path}: requires unsupported glTF extension(s): {}", names.join(", "))]
    UnsupportedRequiredExtension {
        /// The scene file.
        path: PathBuf,
        /// The extensions listed in `extensionsRequired` that we lack.
        names: Vec<String>,
    },
    /// Valid syntax, impossible content (for example an index past the vertex count).
    #[error("{path}: {what}")]
    Invalid {
        /// The scene file.
        path: PathBuf,
        /// What is wrong and where.
        what: String,
    },
}
