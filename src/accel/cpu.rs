//! What the processor offers, found once: the grid's queries and the top level's have
//! versions compiled for AVX2 and pick them at run time.

/// True when the processor has what the queries' versions compiled for AVX2 use: AVX2 for
/// a block's eight lanes and the top level's eight box lanes, POPCNT for an occupied cell's rank (without it, `count_ones` is
/// a seventeen-instruction bit trick on every step into an occupied cell), BMI1 and BMI2
/// for bit tests and shifts. Every x86-64 processor with AVX2 has the other three. The
/// answer is found once and kept as one flag: a query is a few hundred instructions on a
/// small mesh, and four feature tests per query were measurable there.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn x86_fast_path() -> bool {
    static FAST: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FAST.get_or_init(|| {
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("popcnt")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2")
    })
}
