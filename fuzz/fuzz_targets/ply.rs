//! The PLY reader on arbitrary bytes: errors are fine, panics and hangs are not.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = gridtrace::load::ply::parse_mesh(data, std::path::Path::new("fuzz.ply"), data.len() as u64);
});
