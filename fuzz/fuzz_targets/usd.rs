//! The USD loader on arbitrary bytes, as text (`.usda`) and binary (`.usdc`) layers: errors
//! are fine, panics and hangs are not.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("gridtrace-fuzz-usd-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let name = if data.starts_with(b"PXR-USDC") { "fuzz.usdc" } else { "fuzz.usda" };
    let path = dir.join(name);
    if std::fs::write(&path, data).is_ok() {
        let _ = gridtrace::load::usd::load(&path);
    }
});
