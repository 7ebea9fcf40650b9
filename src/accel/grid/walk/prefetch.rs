//! Asking the processor to start loading memory the walk will soon read, so that the waits
//! for several cache misses overlap instead of following one another. On the full dragon a
//! read from memory takes about 170 ns (a pointer chase over 32 MB or more on the
//! development machine), several times a whole step of the walk.

/// Starts loading every cache line of `value` into all levels of the cache. A hint: it
/// changes no value and cannot fault; on other processors than x86-64 it does nothing.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let base = (value as *const T).cast::<i8>();
        for line in (0..std::mem::size_of::<T>()).step_by(64) {
            // SAFETY: a prefetch only hints at an address (here inside `value`) and never
            // faults; SSE is part of every x86_64 processor.
            unsafe {
                std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                    base.wrapping_add(line),
                )
            };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
