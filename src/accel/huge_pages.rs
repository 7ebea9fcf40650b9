//! Large arrays of the accelerators on 2 MiB pages where the system offers them
//! (Linux transparent huge pages in `madvise` mode, the common default): a ray's walk reads
//! a few blocks scattered over a hundred megabytes, and with 4 KiB pages nearly each of
//! those reads also misses the TLB; the build's first writes to a fresh array also fault
//! once per 4 KiB page. Embree does the same on Linux (its `hugepages` option).

/// Arrays smaller than this stay as they are (a huge page would mostly hold nothing).
const WORTHWHILE: usize = 4 << 20;

/// An empty vector with room for `capacity` elements, its memory advised to be backed by
/// huge pages (a hint: where the system ignores it, nothing changes).
pub(crate) fn vec_with_capacity<T>(capacity: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(capacity);
    #[cfg(target_os = "linux")]
    advise(v.as_ptr() as usize, v.capacity() * std::mem::size_of::<T>());
    v
}

/// `len` copies of `value`, on huge pages where the system offers them: for the build's
/// large working arrays, whose first writes would otherwise fault once per 4 KiB page.
pub(crate) fn filled<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut v = vec_with_capacity(len);
    v.resize(len, value);
    v
}

/// Advises the whole 2 MiB pages within `bytes` bytes from `start` (madvise needs
/// page-aligned ranges) to be huge pages.
#[cfg(target_os = "linux")]
fn advise(start: usize, bytes: usize) {
    const HUGE: usize = 2 << 20;
    if bytes < WORTHWHILE {
        return;
    }
    let first = start.next_multiple_of(HUGE);
    let end = (start + bytes) / HUGE * HUGE;
    if end > first {
        // SAFETY: madvise only changes how the kernel backs these pages, which lie inside
        // the caller's own allocation; it reads and writes no memory.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vector_has_the_room_asked_for_and_is_usable() {
        for capacity in [0, 10, WORTHWHILE, 3 * WORTHWHILE + 12_345] {
            let mut v: Vec<u8> = vec_with_capacity(capacity);
            assert!(v.is_empty() && v.capacity() >= capacity);
            v.resize(capacity, 7);
            assert!(v.iter().all(|&b| b == 7));
        }
    }
}
