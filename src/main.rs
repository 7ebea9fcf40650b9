//! The `gridtrace` command: render a scene file to an image.

fn main() {
    // Errors reach the user as one line, so the USD reader's errors need no backtraces;
    // capturing one takes a process-wide lock, which a USD stage's probe, forked while
    // another thread held it, would wait on for ever. Set before any thread starts.
    if std::env::var_os("RUST_LIB_BACKTRACE").is_none() {
        // SAFETY: the process has one thread here.
        unsafe { std::env::set_var("RUST_LIB_BACKTRACE", "0") };
    }
    std::process::exit(gridtrace::cli::main());
}
