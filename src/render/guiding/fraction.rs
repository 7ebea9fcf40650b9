//! How often each region lets the guide propose directions: the share α of the mixture
//! α·p_guide + (1 − α)·p_bsdf, learned per region from the training records (after Müller
//! 2019, "Practical path guiding in production", §10, which learns it by gradient descent).
//!
//! Here it is chosen among a few fixed shares by the second moment of the one-sample
//! estimator each share would give. A record drawn with share α₀ carries the estimate
//! E = F/p_α₀ of its vertex's integral; the second moment with share α is
//! ∫ F²/p_α = E_α₀[E²·p_α₀/p_α], so every candidate is scored from the same records. The
//! least second moment is the least variance, since every share gives the same mean:
//! any choice leaves the image unbiased, and a region where the guide only adds noise
//! (where cosine sampling already aims at what lights it) can fall back to the BSDF alone
//! and skip the guide's lookups.
//!
//! The scores are summed in 128-bit fixed point, exactly, so they — and the shares chosen —
//! do not depend on the order in which threads add records.

use std::sync::atomic::{AtomicU64, Ordering};

/// The shares a region may choose.
pub const CANDIDATES: [f32; 5] = [0.0, 0.1, 0.25, 0.5, 0.75];

/// The share of every region before its first choice: none. The first pass's guide is
/// uniform, and proposing half the directions from it added noise to the image's first
/// sample everywhere; its records still score the shares for the guide it learns.
pub const INITIAL: f32 = 0.0;

/// Fewest records a region must gather in a pass to choose its share from them.
const MIN_RECORDS: u64 = 64;

/// Fixed-point scale of the scores: terms down to 2⁻³² count.
const SCALE: f64 = 4_294_967_296.0;

/// A sum of non-negative terms in 128-bit fixed point, added to from many threads: the low
/// word by atomic addition, and a carry into the high word whenever it wraps, so the sum
/// is exact whatever the order.
#[derive(Debug, Default)]
struct ExactSum {
    low: AtomicU64,
    high: AtomicU64,
}

impl ExactSum {
    fn add(&self, term: f64) {
        // `as` saturates: a term beyond 2⁶⁴ fixed-point units (4·10⁹) counts as that much.
        let units = (term * SCALE) as u64;
        let before = self.low.fetch_add(units, Ordering::Relaxed);
        if before.checked_add(units).is_none() {
            self.high.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn value(&self) -> u128 {
        (u128::from(self.high.load(Ordering::Relaxed)) << 64)
            | u128::from(self.low.load(Ordering::Relaxed))
    }
}

/// A region's scores for the current pass: per candidate share, the sum of E²·p_α₀/p_α.
#[derive(Debug, Default)]
pub struct Scores {
    sums: [ExactSum; CANDIDATES.len()],
}

impl Scores {
    /// Adds a record: the estimate `estimate` (luminance of F/p_α₀) of a direction the
    /// guide gives density `guide_pdf` and the BSDF `bsdf_pdf`, drawn with share `alpha`.
    pub fn add(&self, estimate: f32, guide_pdf: f32, bsdf_pdf: f32, alpha: f32) {
        if !(estimate > 0.0 && estimate.is_finite()) {
            return;
        }
        let mix = |a: f32| f64::from(a * guide_pdf + (1.0 - a) * bsdf_pdf);
        let drawn = mix(alpha);
        let square = f64::from(estimate) * f64::from(estimate);
        for (sum, &candidate) in self.sums.iter().zip(&CANDIDATES) {
            let p = mix(candidate);
            // A share that could not have drawn this direction misses a part of F: its
            // variance is unbounded, which the saturating sum records as the largest term.
            sum.add(if p > 0.0 {
                square * drawn / p
            } else {
                f64::INFINITY
            });
        }
    }

    /// The share with the least score, or `current` when a pass of `records` records is
    /// too few to choose from (ties go to the larger share: the first found is kept).
    pub fn choose(&self, records: u64, current: f32) -> f32 {
        if records < MIN_RECORDS {
            return current;
        }
        let scores = self.sums.each_ref().map(ExactSum::value);
        let mut best = CANDIDATES.len() - 1;
        for k in (0..CANDIDATES.len()).rev() {
            if scores[k] < scores[best] {
                best = k;
            }
        }
        CANDIDATES[best]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampler::Sampler;

    /// Scores `Scores` gathers from 20,000 directions x ∈ [0, 1] drawn from the mixture of
    /// a guide with density 3x² and a BSDF with density 1 at share ½, for integrand `f`.
    fn chosen(f: impl Fn(f32) -> f32) -> f32 {
        let scores = Scores::default();
        let (guide, bsdf) = (|x: f32| 3.0 * x * x, |_: f32| 1.0);
        for i in 0..20_000u32 {
            let u = Sampler::for_sample(3, 0, i).uniform2();
            let x = if u.x < 0.5 { u.y.cbrt() } else { u.y };
            let p = 0.5 * guide(x) + 0.5 * bsdf(x);
            scores.add(f(x) / p, guide(x), bsdf(x), 0.5);
        }
        scores.choose(20_000, 0.5)
    }

    #[test]
    fn an_integrand_shaped_as_the_guide_chooses_the_largest_share() {
        assert_eq!(chosen(|x| 3.0 * x * x), 0.75);
    }

    #[test]
    fn an_integrand_shaped_as_the_bsdf_chooses_the_bsdf_alone() {
        assert_eq!(chosen(|_| 1.0), 0.0);
    }

    #[test]
    fn an_integrand_both_shapes_serve_chooses_a_middle_share() {
        let share = chosen(|x| 0.5 + 1.5 * x * x);
        assert!(share > 0.0 && share < 0.75, "share {share}");
    }

    #[test]
    fn sums_are_exact_across_the_low_word() {
        let sum = ExactSum::default();
        for _ in 0..3 {
            sum.add(3.0e9);
        }
        let units = (3.0e9 * SCALE) as u64;
        assert_eq!(sum.value(), 3 * u128::from(units));
    }

    #[test]
    fn too_few_records_keep_the_current_share() {
        let scores = Scores::default();
        scores.add(1.0, 0.0, 1.0, 0.5);
        assert_eq!(scores.choose(MIN_RECORDS - 1, 0.25), 0.25);
    }
}
