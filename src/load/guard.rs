//! Third-party decoders run on files from strangers, and a bug in one must not take the
//! program down: [`catching_panics`] turns a panic inside them into an error message, and
//! keeps the panic's report off the terminal (the error names the file instead).

use std::cell::Cell;
use std::sync::Once;

thread_local! {
    /// True while this thread runs code under [`catching_panics`].
    static CATCHING: Cell<bool> = const { Cell::new(false) };
}

/// `run()`, or the panic's message if it panics.
pub fn catching_panics<R>(run: impl FnOnce() -> R) -> Result<R, String> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let report = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CATCHING.with(Cell::get) {
                report(info);
            }
        }));
    });
    let outer = CATCHING.with(|c| c.replace(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(run));
    CATCHING.with(|c| c.set(outer));
    result.map_err(|panic| {
        panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("unknown failure")
            .to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message_and_a_value_passes_through() {
        assert_eq!(catching_panics(|| 7), Ok(7));
        let slice: &[u8] = &[1, 2];
        let index = slice.len() + 3;
        let message = catching_panics(|| slice[index]).unwrap_err();
        assert!(message.contains("out of bounds"), "{message}");
    }
}
