//! The glTF/GLB loader on arbitrary bytes, loaded from a folder that holds a buffer
//! (`quad.bin`) and an image (`tex.png`) beside the scene, under a root that also holds a
//! secret outside it (`../secret.txt`): errors are fine; panics, hangs, and any message
//! holding the secret are not.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

const SECRET: &str = "FUZZSECRET-do-not-print";

fn scene_folder() -> &'static PathBuf {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("gridtrace-fuzz-gltf-{}", std::process::id()));
        let scene = root.join("scene");
        std::fs::create_dir_all(&scene).unwrap();
        std::fs::write(root.join("secret.txt"), SECRET.repeat(8)).unwrap();
        let mut quad = Vec::new();
        for p in [[-1f32, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]] {
            p.iter().for_each(|c| quad.extend_from_slice(&c.to_le_bytes()));
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            quad.extend_from_slice(&i.to_le_bytes());
        }
        std::fs::write(scene.join("quad.bin"), quad).unwrap();
        let image = gridtrace::render::Image::new(2, 2);
        gridtrace::output::write_image(&scene.join("tex.png"), &image).unwrap();
        scene
    })
}

fuzz_target!(|data: &[u8]| {
    let name = if data.starts_with(b"glTF") { "fuzz.glb" } else { "fuzz.gltf" };
    let path = scene_folder().join(name);
    let said = match gridtrace::load::gltf::load_bytes(data, &path) {
        Ok(loaded) => loaded.warnings.join("\n"),
        Err(e) => e.to_string(),
    };
    assert!(!said.contains("FUZZSECRET"), "{said}");
});
