//! Development-only linking of Embree 4: when `tools/dev/install-embree.sh` has put the library
//! in `.embree4/`, the tests and benchmarks (which use it as an oracle) link
//! against it and find it at run time through an rpath. The renderer itself never does.

use std::path::PathBuf;

fn main() {
    let dir =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo")).join(".embree4");
    println!("cargo:rerun-if-changed={}", dir.display());
    if dir.join("libembree4.so").exists() {
        println!("cargo:rustc-link-search=native={}", dir.display());
        for kind in ["tests", "benches"] {
            println!("cargo:rustc-link-arg-{kind}=-Wl,-rpath,{}", dir.display());
        }
    }
}
