//! One portable body, compiled for each instruction set the processor may have, and chosen
//! at run time: what the processor offers is found once ([`x86_level`]), and [`dispatch`]
//! runs a [`Kernel`] compiled for the widest set it has, up to the widest the kernel gains
//! from (the grid's queries: AVX-512; the top level and the build: AVX2). Every version
//! runs the same operations on the same values, so every version gives the same answers.

/// The instruction sets kernels have versions for, from least to most (the last two on
/// x86-64 only).
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

/// Work whose body is written once and compiled for several instruction sets: `run` is
/// inlined into each version [`dispatch`] compiles. `FUSED` says the version has fused
/// multiply-adds (FMA), for bodies that choose `mul_add` only where it is one instruction.
pub(crate) trait Kernel {
    /// What the work returns.
    type Output;
    /// Does the work.
    fn run<const FUSED: bool>(self) -> Self::Output;
}

/// Runs `kernel` compiled for the widest instruction set this processor has, but none
/// wider than `widest` (where a kernel was measured to gain nothing more).
#[inline(always)]
pub(crate) fn dispatch<K: Kernel>(
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))] widest: X86Level,
    kernel: K,
) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    // SAFETY (each arm): the processor has the features the version enables, as
    // `x86_level` found.
    match x86_level().min(widest) {
        X86Level::Avx512 => return unsafe { run_avx512(kernel) },
        X86Level::Avx2 => return unsafe { run_avx2(kernel) },
        X86Level::Baseline => {}
    }
    kernel.run::<false>()
}

/// `kernel` compiled for AVX2 and its companions ([`X86Level::Avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2")]
fn run_avx2<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<true>()
}

/// `kernel` compiled for AVX-512 besides ([`X86Level::Avx512`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2,avx512f,avx512vl,avx512bw,avx512dq")]
fn run_avx512<K: Kernel>(kernel: K) -> K::Output {
    kernel.run::<true>()
}
