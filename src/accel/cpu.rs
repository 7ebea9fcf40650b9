//! What the processor offers, found once: the grid's queries and the top level's have
//! versions compiled for AVX2 (and the grid's for AVX-512 too) and pick them at run time.

/// The instruction sets the queries have versions for, from least to most.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum X86Level {
    /// Baseline x86-64 (SSE2): the portable versions.
    Baseline,
    /// AVX2 for a block's eight lanes and the top level's eight box lanes, POPCNT for an
    /// occupied cell's rank (without it, `count_ones` is a seventeen-instruction bit trick
    /// on every step into an occupied cell), BMI1 and BMI2 for bit tests and shifts, FMA
    /// for the walk's fused multiply-adds (the grid's queries). Every x86-64 processor with
    /// AVX2 has the other four.
    Avx2,
    /// AVX-512 F, VL, BW and DQ besides: the walk's 128-bit lanes and the blocks' 256-bit
    /// ones gain mask registers for their comparisons and selections, and 32 vector
    /// registers (the grid's queries 1.02–1.08× as fast on the dragons; measured at
    /// 6899122).
    Avx512,
}

/// The richest [`X86Level`] this processor has. The answer is found once and kept: a query
/// is a few hundred instructions on a small mesh, and four feature tests per query were
/// measurable there.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn x86_level() -> X86Level {
    static LEVEL: std::sync::OnceLock<X86Level> = std::sync::OnceLock::new();
    *LEVEL.get_or_init(|| {
        let avx2 = std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
            && std::is_x86_feature_detected!("popcnt")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2");
        let avx512 = std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512vl")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512dq");
        match (avx2, avx512) {
            (true, true) => X86Level::Avx512,
            (true, false) => X86Level::Avx2,
            (false, _) => X86Level::Baseline,
        }
    })
}

/// True when the processor has what the versions compiled for AVX2 use ([`X86Level::Avx2`]).
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn x86_fast_path() -> bool {
    x86_level() >= X86Level::Avx2
}
