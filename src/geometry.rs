//! The geometry every layer shares: axis-aligned boxes, the bounds on floating-point
//! rounding error (Higham 2002; pbrt-v4 §6.8) that let rays leave surfaces and cross slabs
//! without an epsilon, and which triangles are too degenerate ever to be hit.

use glam::{Affine3A, Mat3A, Vec3, Vec3A};

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: the identity for [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The smallest box holding all `points`.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(p))
    }

    /// This box grown to hold `p`.
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box holding both.
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Side lengths.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Centre point.
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The bounding box of this box after an affine transform.
    pub fn transformed(&self, m: &Affine3A) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        Aabb::from_points(self.corners().map(|c| m.transform_point3(c)))
    }
}

/// γ(n) = nε / (1 − nε), the bound on the relative error of n chained floating-point
/// operations (Higham 2002; pbrt-v4 §6.8.1), with ε = 2⁻²⁴.
pub const fn gamma(n: i32) -> f32 {
    let e = n as f32 * (f32::EPSILON * 0.5);
    e / (1.0 - e)
}

/// Points transformed by `m`, each with a bound on the rounding error that added (the
/// matrix's absolute values taken once for all of them).
pub fn transform_points_with_error<const N: usize>(
    m: &Affine3A,
    points: [Vec3; N],
) -> [(Vec3, Vec3); N] {
    // In SIMD lanes (`Mat3A`, `Vec3A`): the same operations in the same order as in `Vec3`.
    let abs = Mat3A::from_cols(
        m.matrix3.x_axis.abs(),
        m.matrix3.y_axis.abs(),
        m.matrix3.z_axis.abs(),
    );
    let translation = m.translation.abs();
    let mut placed = [(Vec3::ZERO, Vec3::ZERO); N];
    for (out, p) in placed.iter_mut().zip(points) {
        let p = Vec3A::from(p);
        *out = (
            m.transform_point3a(p).into(),
            (gamma(3) * (abs * p.abs() + translation)).into(),
        );
    }
    placed
}

/// Interpolates three corners (with their error bounds) at barycentrics (b0, b1, b2), and
/// bounds the result's error (pbrt-v4 §6.8.4: γ(7)·Σ|bᵢpᵢ|, plus the corners' own error).
pub fn interpolate_with_error(corners: [(Vec3, Vec3); 3], b: [f32; 3]) -> (Vec3, Vec3) {
    let mut point = Vec3A::ZERO;
    let mut error = Vec3A::ZERO;
    for ((p, e), w) in corners.into_iter().zip(b) {
        let (p, e) = (Vec3A::from(p), Vec3A::from(e));
        point += w * p;
        error += (w * p).abs() * gamma(7) + w.abs() * e;
    }
    (point.into(), error.into())
}

/// A ray origin moved off a surface just far enough that the rounding error of `p` cannot
/// put it on the wrong side: along the normal by the error bound projected on it, towards
/// the side `w` leaves by, then rounded away from the surface (pbrt-v4 §6.8.6). Because the
/// bound scales with the coordinates, this works at any scene scale, unlike a fixed epsilon.
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    step_along(p + offset, offset)
}

/// Each coordinate of `p` moved to the next float in the direction of the same coordinate
/// of `offset` (`next_up` where it is positive, `next_down` where negative). On x86-64 all
/// three at once on their bits, without branches: which way each goes is a coin toss for
/// the branch predictor (a tenth of a render's mispredictions were here).
#[cfg(target_arch = "x86_64")]
fn step_along(p: Vec3, offset: Vec3) -> Vec3 {
    use std::arch::x86_64::{
        __m128, _mm_add_epi32, _mm_and_si128, _mm_andnot_si128, _mm_castps_si128, _mm_castsi128_ps,
        _mm_cmpeq_ps, _mm_cmpgt_epi32, _mm_cmpgt_ps, _mm_cmplt_ps, _mm_or_si128, _mm_set1_epi32,
        _mm_setzero_ps, _mm_srai_epi32, _mm_xor_si128,
    };
    let (x, o) = (
        __m128::from(Vec3A::from(p)),
        __m128::from(Vec3A::from(offset)),
    );
    // SAFETY: SSE2, which these intrinsics need, is part of x86_64.
    let stepped = unsafe {
        let zero = _mm_setzero_ps();
        let up = _mm_castps_si128(_mm_cmpgt_ps(o, zero));
        let down = _mm_castps_si128(_mm_cmplt_ps(o, zero));
        let moving = _mm_or_si128(up, down);
        let sign = _mm_set1_epi32(i32::MIN);
        // A zero that moves takes the sign of its direction, so that one step away from zero
        // (magnitude + 1) gives the smallest subnormal on that side.
        let leaving_zero = _mm_and_si128(_mm_castps_si128(_mm_cmpeq_ps(x, zero)), moving);
        let bits = _mm_castps_si128(x);
        let bits = _mm_or_si128(
            _mm_andnot_si128(leaving_zero, bits),
            _mm_and_si128(leaving_zero, _mm_and_si128(down, sign)),
        );
        // Bits are sign and magnitude: + 1 moves away from zero, − 1 (all ones) towards it.
        let towards_zero = _mm_xor_si128(_mm_srai_epi32(bits, 31), down);
        let step = _mm_and_si128(_mm_or_si128(towards_zero, _mm_set1_epi32(1)), moving);
        // NaN stays, and so does an infinity moving outwards (as `next_up`/`next_down` do).
        let magnitude = _mm_andnot_si128(sign, bits);
        let not_finite = _mm_cmpgt_epi32(magnitude, _mm_set1_epi32(0x7f7f_ffff));
        let nan = _mm_cmpgt_epi32(magnitude, _mm_set1_epi32(0x7f80_0000));
        let stays = _mm_or_si128(nan, _mm_andnot_si128(towards_zero, not_finite));
        let stepped = _mm_add_epi32(bits, _mm_andnot_si128(stays, step));
        _mm_castsi128_ps(stepped)
    };
    Vec3A::from(stepped).into()
}

/// [`step_along`] one coordinate at a time.
#[cfg(any(not(target_arch = "x86_64"), test))]
fn step_along_by_axis(mut p: Vec3, offset: Vec3) -> Vec3 {
    for axis in 0..3 {
        if offset[axis] > 0.0 {
            p[axis] = p[axis].next_up();
        } else if offset[axis] < 0.0 {
            p[axis] = p[axis].next_down();
        }
    }
    p
}

#[cfg(not(target_arch = "x86_64"))]
use step_along_by_axis as step_along;

/// True when the triangle (`v0`, `v0 + e1`, `v0 + e2`) has no area or non-finite corners;
/// such triangles are never hit, so loaders warn about them and grids leave them out.
pub fn is_degenerate(v0: Vec3, e1: Vec3, e2: Vec3) -> bool {
    let n = e1.cross(e2);
    let scale = e1.length_squared().max(e2.length_squared());
    !(v0.is_finite() && e1.is_finite() && e2.is_finite())
        || n.length_squared() <= 1e-14 * scale * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three lanes at once step exactly as `next_up`/`next_down` one at a time, bit for
    /// bit: zeros of both signs, subnormals, the largest floats, infinities, NaN, and random
    /// bit patterns, each moved up, down and not at all.
    #[test]
    fn stepping_all_lanes_equals_next_up_and_next_down() {
        let mut values = vec![
            0.0,
            -0.0,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            1.0,
            -1.0,
        ];
        let mut state = 0x9e37_79b9_u32;
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            values.push(f32::from_bits(state));
        }
        let directions = [1.0, -1.0, 0.0, -0.0, f32::NAN];
        for (k, &x) in values.iter().enumerate() {
            let p = Vec3::new(x, values[(k * 7 + 3) % values.len()], -x);
            for (i, &dx) in directions.iter().enumerate() {
                let offset = Vec3::new(dx, directions[(i + 1) % 5], directions[(i + 3) % 5]);
                let lanes = step_along(p, offset);
                let by_axis = step_along_by_axis(p, offset);
                for axis in 0..3 {
                    let (a, b) = (lanes[axis], by_axis[axis]);
                    assert!(
                        a.to_bits() == b.to_bits() || a.is_nan() && b.is_nan(),
                        "{:?} moved by {:?}: {a:?} against {b:?}",
                        p[axis],
                        offset[axis]
                    );
                }
            }
        }
    }
}
