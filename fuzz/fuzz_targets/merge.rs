//! `gridtrace merge` on an arbitrary file as a part: its header, its record and its pixels
//! are read and checked; errors are fine, panics, aborts and allocations the file cannot
//! justify are not (run with -rss_limit_mb and -malloc_limit_mb).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("gridtrace-fuzz-merge-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("part.exr");
    if std::fs::write(&path, data).is_ok() {
        let _ = gridtrace::output::merge::merge_files(&[path], None);
    }
});
