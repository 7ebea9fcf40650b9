//! The USD loader on arbitrary text layers (`.usda`), read in-process unless the text names
//! another layer (then the loader's forked probe runs, as for any user): errors are fine,
//! panics are not. Faster than `usd`, whose binary inputs each cost a fork.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("gridtrace-fuzz-usda-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("fuzz.usda");
    if std::fs::write(&path, data).is_ok() {
        let _ = gridtrace::load::usd::load(&path);
    }
});
