//! The memory a run may use: one budget for the whole process, against which every
//! allocation whose size comes from a file or an option (a film, a merged part, a decoded
//! image, a decompressed mesh) is checked before it is made, so a hostile or mistaken
//! input gets a clear error instead of an abort when the allocation fails.
//!
//! The process's heap is accounted as it is used: the global allocator ([`Accounting`])
//! keeps a running total of the bytes allocated, so a check compares a request with what
//! is left — the budget minus everything already held, the copies made after earlier
//! checks included — not with the whole budget.
//!
//! The budget is the smallest of 80 % of the machine's physical memory (the rest is the
//! system's), the process's address-space and data-segment limits (`ulimit -v`,
//! `ulimit -d`, `prlimit`) less headroom for what the heap does not hold (code, thread
//! stacks, the allocator's own reservations), or what `--max-memory` says.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

/// Set by `--max-memory`; 0 means "the machine's".
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// Bytes the process holds on the heap now.
static IN_USE: AtomicUsize = AtomicUsize::new(0);

/// Bytes promised to work under way (a decode and the copies that follow it) and not yet
/// all allocated: counted as held, so parallel work cannot take them too.
static RESERVED: AtomicU64 = AtomicU64::new(0);

/// Set in a child process that reads a file to see whether the reader survives it: there
/// a failed allocation ends the process at once with an exit status that says why
/// ([`EXIT_IMPOSSIBLE_ALLOCATION`] or [`EXIT_OUT_OF_MEMORY`]) instead of an abort.
static EXIT_ON_ALLOCATION_FAILURE: AtomicBool = AtomicBool::new(false);

/// Exit status of a probe child whose reader asked for more than the whole budget at once:
/// a count read from a corrupt file.
pub const EXIT_IMPOSSIBLE_ALLOCATION: i32 = 86;

/// Exit status of a probe child that ran out of memory with requests each within budget.
pub const EXIT_OUT_OF_MEMORY: i32 = 87;

/// Makes a failed allocation end this process with a telling exit status; for a forked
/// probe child only (it runs no destructors).
pub fn exit_on_allocation_failure() {
    EXIT_ON_ALLOCATION_FAILURE.store(true, Ordering::Relaxed);
}

/// Called with the size of a failed allocation: ends a probe child, else returns.
fn allocation_failed(size: usize) {
    if EXIT_ON_ALLOCATION_FAILURE.load(Ordering::Relaxed) {
        let status = if size as u64 > memory_budget() {
            EXIT_IMPOSSIBLE_ALLOCATION
        } else {
            EXIT_OUT_OF_MEMORY
        };
        // SAFETY: ends the process at once; nothing shared is left half done that matters
        // to a child whose only output is its exit status.
        unsafe { libc::_exit(status) };
    }
}

/// The system allocator, counting what it hands out in [`IN_USE`].
pub struct Accounting;

// SAFETY: every call is passed to the system allocator unchanged; only a counter is kept.
unsafe impl GlobalAlloc for Accounting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is System's.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            allocation_failed(layout.size());
        } else {
            IN_USE.fetch_add(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as above.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            allocation_failed(layout.size());
        } else {
            IN_USE.fetch_add(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) };
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as above.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            allocation_failed(new_size);
        } else {
            if new_size >= layout.size() {
                IN_USE.fetch_add(new_size - layout.size(), Ordering::Relaxed);
            } else {
                IN_USE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Accounting = Accounting;

/// Bytes the process holds on the heap now.
pub fn memory_in_use() -> u64 {
    IN_USE.load(Ordering::Relaxed) as u64
}

/// An allocation larger than what is left of the budget, refused before it was made.
#[derive(Debug, thiserror::Error)]
#[error(
    "{what} needs {} of memory, more than the {} left of the {} this run may use (--max-memory)",
    Bytes(*needed),
    Bytes(*left),
    Bytes(*budget)
)]
pub struct OverBudget {
    /// What would have been allocated ("a 16384x16384 film").
    pub what: String,
    /// Bytes it needs.
    pub needed: u64,
    /// Bytes left when it was asked for.
    pub left: u64,
    /// Bytes the run may use.
    pub budget: u64,
}

/// Sets the budget (`--max-memory`); 0 returns to the machine's.
pub fn set_memory_budget(bytes: u64) {
    MAX_MEMORY.store(bytes, Ordering::Relaxed);
}

/// Bytes this run may hold in all.
pub fn memory_budget() -> u64 {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => machine_memory(),
        set => set,
    }
}

/// Bytes this run may still allocate: the budget less what the heap holds and what is
/// reserved.
pub fn memory_left() -> u64 {
    memory_budget()
        .saturating_sub(memory_in_use())
        .saturating_sub(RESERVED.load(Ordering::Relaxed))
}

/// Refuses `needed` bytes for `what` if they exceed what is left of the budget.
pub fn check_memory(what: impl FnOnce() -> String, needed: u64) -> Result<(), OverBudget> {
    let budget = memory_budget();
    let left = memory_left();
    if needed > left {
        return Err(OverBudget {
            what: what(),
            needed,
            left,
            budget,
        });
    }
    Ok(())
}

/// Bytes set aside for a sequence of allocations (a decoder's output and the copies made
/// from it) checked as one: released when dropped, by which time they are held or freed.
#[must_use]
pub struct Reservation(u64);

impl Reservation {
    /// The bytes reserved.
    pub fn bytes(&self) -> u64 {
        self.0
    }
}

impl Drop for Reservation {
    fn drop(&mut self) {
        RESERVED.fetch_sub(self.0, Ordering::Relaxed);
    }
}

/// Checks `needed` bytes for `what` and sets them aside until the reservation is dropped.
pub fn reserve_memory(
    what: impl FnOnce() -> String,
    needed: u64,
) -> Result<Reservation, OverBudget> {
    check_memory(what, needed)?;
    RESERVED.fetch_add(needed, Ordering::Relaxed);
    Ok(Reservation(needed))
}

/// `count` items of `T` in bytes, saturating.
pub fn bytes_of<T>(count: u64) -> u64 {
    count.saturating_mul(std::mem::size_of::<T>() as u64)
}

/// What a process limit leaves the heap: the limit less an eighth of it, and at least
/// 256 MiB, for the mappings the heap does not count (code, thread stacks, the allocator's
/// per-thread arenas).
fn heap_under(limit: u64) -> u64 {
    limit.saturating_sub((limit / 8).max(256 << 20))
}

/// 80 % of physical memory, capped by what the process's address-space and data limits
/// leave the heap.
#[cfg(unix)]
fn machine_memory() -> u64 {
    // SAFETY: sysconf and getrlimit only write to the struct passed by pointer.
    let physical = unsafe {
        let pages = libc::sysconf(libc::_SC_PHYS_PAGES);
        let size = libc::sysconf(libc::_SC_PAGESIZE);
        if pages > 0 && size > 0 {
            (pages as u64).saturating_mul(size as u64) / 5 * 4
        } else {
            u64::MAX
        }
    };
    let limit = |resource| {
        let mut rlimit = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: a valid resource and a valid pointer to write the limits to.
        let ok = unsafe { libc::getrlimit(resource, &mut rlimit) } == 0;
        if ok && rlimit.rlim_cur != libc::RLIM_INFINITY {
            heap_under(rlimit.rlim_cur)
        } else {
            u64::MAX
        }
    };
    physical
        .min(limit(libc::RLIMIT_AS))
        .min(limit(libc::RLIMIT_DATA))
}

#[cfg(not(unix))]
fn machine_memory() -> u64 {
    u64::MAX
}

/// A size in bytes for messages: "10.7 GB".
pub struct Bytes(pub u64);

impl std::fmt::Display for Bytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let b = self.0 as f64;
        match self.0 {
            0..1_000_000 => write!(f, "{:.1} kB", b / 1e3),
            1_000_000..1_000_000_000 => write!(f, "{:.1} MB", b / 1e6),
            _ => write!(f, "{:.1} GB", b / 1e9),
        }
    }
}

/// Parses a size for `--max-memory`: bytes, or a number with a suffix K, M, G or T
/// (powers of 1024; "8G", "512M").
pub fn parse_size(text: &str) -> Result<u64, String> {
    let text = text.trim();
    let (number, unit) = match text.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => text.split_at(i),
        None => (text, ""),
    };
    let scale: u64 = match unit.to_ascii_uppercase().trim_end_matches(['B', 'I']) {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return Err(format!("'{text}' is not a size (use bytes or K, M, G, T)")),
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a size (use bytes or K, M, G, T)"))?;
    if !(value.is_finite() && value >= 1.0) {
        return Err(format!("'{text}' is not a positive size"));
    }
    Ok((value * scale as f64).min(u64::MAX as f64) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_suffixes() {
        assert_eq!(parse_size("4096").unwrap(), 4096);
        assert_eq!(parse_size("8G").unwrap(), 8 << 30);
        assert_eq!(parse_size("1.5k").unwrap(), 1536);
        assert_eq!(parse_size("512MiB").unwrap(), 512 << 20);
        assert!(parse_size("-1G").is_err() && parse_size("lots").is_err());
    }

    #[test]
    fn the_machine_has_some_memory() {
        let budget = machine_memory();
        assert!(budget > 1 << 20, "{budget}");
        let refused = check_memory(|| "a test".into(), u64::MAX).unwrap_err();
        assert!(refused.to_string().starts_with("a test needs"), "{refused}");
    }

    #[test]
    fn what_is_held_is_counted_against_the_budget() {
        let before = memory_in_use();
        let held = vec![1u8; 64 << 20];
        // Other tests allocate and free at the same time: allow them a margin.
        assert!(memory_in_use() + (16 << 20) >= before + (64 << 20));
        let left = memory_left();
        assert!(left <= memory_budget() - (48 << 20), "{left}");
        drop(held);
    }

    #[test]
    fn a_process_limit_leaves_headroom_outside_the_heap() {
        assert_eq!(heap_under(2 << 30), (2 << 30) - (256 << 20));
        assert_eq!(heap_under(16 << 30), 14 << 30);
        assert_eq!(heap_under(100 << 20), 0);
    }
}
