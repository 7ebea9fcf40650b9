//! Inputs the fuzzers (`fuzz/`, run with `cargo fuzz`) found crashing, kept so they stay
//! fixed: each file under `tests/data/fuzz_crashes/<target>/` goes through the same code as its
//! fuzz target and must come back as an error or a result, never a panic.

use std::path::Path;

use gridtrace::load::{gltf, ply};

fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz_crashes")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files
        .into_iter()
        .map(|p| (p.display().to_string(), std::fs::read(&p).unwrap()))
        .collect()
}

#[test]
fn gltf_crashers_are_errors() {
    let cases = inputs("gltf");
    assert!(!cases.is_empty(), "the gltf crasher corpus is missing");
    for (name, bytes) in cases {
        // Named as the fuzz target names it: by its first bytes.
        let file = if bytes.starts_with(b"glTF") {
            "fuzz.glb"
        } else {
            "fuzz.gltf"
        };
        let result = gltf::load_bytes(&bytes, Path::new(file));
        assert!(result.is_err(), "{name}: expected a clear error");
        let message = result.unwrap_err().to_string();
        assert!(
            message.starts_with(&format!("{file}: ")) && !message.contains('\n'),
            "{name}: {message}"
        );
    }
}

#[test]
fn ply_crashers_are_errors() {
    let cases = inputs("ply");
    assert!(!cases.is_empty(), "the ply crasher corpus is missing");
    for (name, bytes) in cases {
        let result = ply::parse_mesh(bytes.as_slice(), Path::new("fuzz.ply"), bytes.len() as u64);
        let message = result.expect_err(&name).to_string();
        assert!(
            message.starts_with("fuzz.ply: ") && !message.contains('\n'),
            "{name}: {message}"
        );
    }
}

/// Corrupt binary layers on which openusd 0.6 requests impossible allocations (which abort
/// a process): the loader reads them in a child process first, so they come back as errors.
#[test]
fn usd_crashers_are_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_crashes/usd");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "usdc"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "the usd crasher corpus is missing");
    for path in files {
        let result = gridtrace::load::usd::load(&path);
        let message = result
            .expect_err("a corrupt file must be an error")
            .to_string();
        assert!(
            message.contains(&*path.file_name().unwrap().to_string_lossy()),
            "{message}"
        );
    }
}

/// KTX2 images the `gltf_compressed` target found taking the process down (a Zstandard
/// level whose header claims exabytes; a key/value entry that makes the transcoder index
/// past its input; a 392-byte ETC1S file declaring 16,591,168 × 64 texels, which ran the
/// fuzzer out of memory): as a glTF texture, each is a warning naming the image. Under the
/// fuzzer's 1 GiB budget, as under any budget smaller than its 12.7 GB.
#[test]
fn ktx2_crashers_are_warnings() {
    gridtrace::limits::set_memory_budget(1 << 30);
    let cases = inputs("ktx2");
    assert!(!cases.is_empty(), "the ktx2 crasher corpus is missing");
    for (name, bytes) in cases {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("image.ktx2"), &bytes).unwrap();
        let document = r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_texture_basisu"],
            "images":[{"uri":"image.ktx2"}],
            "textures":[{"extensions":{"KHR_texture_basisu":{"source":0}}}],
            "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
            "scenes":[{"nodes":[]}]}"#;
        let path = dir.path().join("scene.gltf");
        std::fs::write(&path, document).unwrap();
        let loaded = gltf::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            loaded
                .warnings
                .iter()
                .any(|w| w.contains("image 0") && w.contains("KTX2")),
            "{name}: {:?}",
            loaded.warnings
        );
    }
}
