//! Scene loaders: each turns one file format into a [`Scene`].

mod error;
pub mod gltf;
pub mod ply;

pub use error::LoadError;

use std::path::Path;

use crate::scene::Scene;

/// A loaded scene and the warnings met on the way (things skipped or approximated).
#[derive(Debug)]
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// One line each, already naming what they concern.
    pub warnings: Vec<String>,
}

/// Loads a scene, choosing the loader by file extension.
pub fn load_scene(path: &Path) -> Result<Loaded, LoadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("gltf" | "glb") => gltf::load(path),
        _ => Err(LoadError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}
