//! A walk's cell coordinates as whole numbers in the lanes of one vector register.
//!
//! The cell a walk lands in is the start of the next step's chain of dependent operations
//! (cell → index → lookup → exit distances → next cell), so it is kept where the lookup and
//! the exit arithmetic both find it without a round trip: integer lanes, from which a
//! macrocell's corner is one `and` away and the float coordinates one conversion, off the
//! chain. Without SSE2 (not x86-64) the same operations run on an [`IVec3`].

use glam::{BVec3A, IVec3, Vec3A};

/// Cell coordinates (x, y, z) as whole numbers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellLanes(
    #[cfg(target_arch = "x86_64")] std::arch::x86_64::__m128i,
    #[cfg(not(target_arch = "x86_64"))] IVec3,
);

#[cfg(target_arch = "x86_64")]
mod lanes {
    pub use std::arch::x86_64::{
        __m128, __m128i, _mm_add_epi32, _mm_and_si128, _mm_andnot_si128, _mm_castps_si128,
        _mm_cmpgt_epi32, _mm_cvtepi32_ps, _mm_cvttps_epi32, _mm_or_si128, _mm_set1_epi32,
        _mm_setzero_si128,
    };
}

impl CellLanes {
    /// All zero.
    #[inline(always)]
    pub fn zero() -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2, which these intrinsics need, is part of x86_64 (likewise below).
        return CellLanes(unsafe { lanes::_mm_setzero_si128() });
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(IVec3::ZERO)
    }

    /// `v` rounded towards zero: one instruction for coordinates known to be in range
    /// (`as` would check each lane for overflow and NaN). Out of range or NaN gives
    /// `i32::MIN` on x86-64.
    #[inline(always)]
    pub fn truncating(v: Vec3A) -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        return CellLanes(unsafe { lanes::_mm_cvttps_epi32(lanes::__m128::from(v)) });
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(v.as_ivec3())
    }

    /// The coordinates as floats (exact: cells number far fewer than 2²⁴ per axis).
    #[inline(always)]
    pub fn to_floats(self) -> Vec3A {
        #[cfg(target_arch = "x86_64")]
        return Vec3A::from(unsafe { lanes::_mm_cvtepi32_ps(self.0) });
        #[cfg(not(target_arch = "x86_64"))]
        self.0.as_vec3a()
    }

    /// The coordinates as an [`IVec3`], for indexing.
    #[inline(always)]
    pub fn ivec3(self) -> IVec3 {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: both types are 16 bytes of plain integers.
            let l = unsafe { std::mem::transmute::<lanes::__m128i, [i32; 4]>(self.0) };
            IVec3::new(l[0], l[1], l[2])
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.0
    }

    /// Lane by lane sum.
    #[inline(always)]
    pub fn add(self, other: CellLanes) -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        return CellLanes(unsafe { lanes::_mm_add_epi32(self.0, other.0) });
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(self.0 + other.0)
    }

    /// Each coordinate rounded down to a multiple of `2^shift` (non-negative coordinates).
    #[inline(always)]
    pub fn round_down(self, shift: u32) -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        return CellLanes(unsafe {
            lanes::_mm_and_si128(self.0, lanes::_mm_set1_epi32(!((1 << shift) - 1)))
        });
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(self.0 & IVec3::splat(!((1 << shift) - 1)))
    }

    /// Each coordinate raised to at least `lo`'s and lowered to at most `hi`'s. (Written
    /// with SSE2 comparisons; compiled with SSE4.1 or later, each half is one `pmaxsd` or
    /// `pminsd`.)
    #[inline(always)]
    pub fn clamp(self, lo: CellLanes, hi: CellLanes) -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        return unsafe {
            let raised = CellLanes::select_lanes(lanes::_mm_cmpgt_epi32(lo.0, self.0), lo, self);
            CellLanes::select_lanes(lanes::_mm_cmpgt_epi32(raised.0, hi.0), hi, raised)
        };
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(self.0.clamp(lo.0, hi.0))
    }

    /// `a` in the lanes of `mask`, `b` in the others.
    #[inline(always)]
    pub fn select(mask: BVec3A, a: CellLanes, b: CellLanes) -> CellLanes {
        #[cfg(target_arch = "x86_64")]
        return CellLanes::select_lanes(
            unsafe { lanes::_mm_castps_si128(lanes::__m128::from(mask)) },
            a,
            b,
        );
        #[cfg(not(target_arch = "x86_64"))]
        CellLanes(IVec3::select(
            glam::BVec3::new(mask.test(0), mask.test(1), mask.test(2)),
            a.0,
            b.0,
        ))
    }
}

#[cfg(target_arch = "x86_64")]
impl CellLanes {
    /// `a` in the lanes where `mask` is all ones, `b` where it is zero.
    #[inline(always)]
    fn select_lanes(mask: lanes::__m128i, a: CellLanes, b: CellLanes) -> CellLanes {
        CellLanes(unsafe {
            lanes::_mm_or_si128(
                lanes::_mm_and_si128(mask, a.0),
                lanes::_mm_andnot_si128(mask, b.0),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_do_what_an_ivec3_does() {
        let c = CellLanes::truncating(Vec3A::new(13.7, 0.2, 2047.0));
        assert_eq!(c.ivec3(), IVec3::new(13, 0, 2047));
        assert_eq!(c.to_floats(), Vec3A::new(13.0, 0.0, 2047.0));
        assert_eq!(c.round_down(3).ivec3(), IVec3::new(8, 0, 2040));
        let step = CellLanes::truncating(Vec3A::new(-1.0, 1.0, 0.0));
        assert_eq!(c.add(step).ivec3(), IVec3::new(12, 1, 2047));
        let mask = BVec3A::new(true, false, true);
        assert_eq!(
            CellLanes::select(mask, c, step).ivec3(),
            IVec3::new(13, 1, 2047)
        );
        assert_eq!(CellLanes::zero().ivec3(), IVec3::ZERO);
        let (lo, hi) = (CellLanes::zero(), CellLanes::truncating(Vec3A::splat(12.0)));
        assert_eq!(c.clamp(lo, hi).ivec3(), IVec3::new(12, 0, 12));
        let below = CellLanes::truncating(Vec3A::new(-3.0, f32::NAN, 5.0));
        assert_eq!(below.clamp(lo, hi).ivec3(), IVec3::new(0, 0, 5));
    }
}
