//! The glTF/GLB loader on arbitrary bytes: errors are fine, panics and hangs are not.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = gridtrace::load::gltf::load_bytes(data, std::path::Path::new("fuzz.glb"));
});
