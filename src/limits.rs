//! The memory a run may use: one budget, checked before every allocation whose size comes
//! from a file or an option (a film, a merged part, a decompressed mesh), so a hostile or
//! mistaken input gets a clear error instead of an abort when the allocation fails.
//!
//! The budget is the smallest of 80 % of the machine's physical memory (the rest is the
//! system's and the scene's) and the process's address-space and data-segment limits
//! (`ulimit -v`, `ulimit -d`, `prlimit`), or what `--max-memory` says.

use std::sync::atomic::{AtomicU64, Ordering};

/// Set by `--max-memory`; 0 means "the machine's".
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// An allocation larger than the budget, refused before it was made.
#[derive(Debug, thiserror::Error)]
#[error(
    "{what} needs {} of memory, more than the {} this run may use (--max-memory)",
    Bytes(*needed),
    Bytes(*budget)
)]
pub struct OverBudget {
    /// What would have been allocated ("a 16384x16384 film").
    pub what: String,
    /// Bytes it needs.
    pub needed: u64,
    /// Bytes the run may use.
    pub budget: u64,
}

/// Sets the budget (`--max-memory`); 0 returns to the machine's.
pub fn set_memory_budget(bytes: u64) {
    MAX_MEMORY.store(bytes, Ordering::Relaxed);
}

/// Bytes this run may allocate in all.
pub fn memory_budget() -> u64 {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => machine_memory(),
        set => set,
    }
}

/// Refuses `needed` bytes for `what` if they exceed the budget.
pub fn check_memory(what: impl FnOnce() -> String, needed: u64) -> Result<(), OverBudget> {
    let budget = memory_budget();
    if needed > budget {
        return Err(OverBudget {
            what: what(),
            needed,
            budget,
        });
    }
    Ok(())
}

/// `count` items of `T` in bytes, saturating.
pub fn bytes_of<T>(count: u64) -> u64 {
    count.saturating_mul(std::mem::size_of::<T>() as u64)
}

/// 80 % of physical memory, capped by the process's address-space and data limits.
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
            rlimit.rlim_cur
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
}
