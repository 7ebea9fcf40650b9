//! The `gridtrace` command: render a scene file to an image.

fn main() {
    std::process::exit(gridtrace::cli::main());
}
