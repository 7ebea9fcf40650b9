//! The box of an occupied cell's triangles within the cell, for grids whose blocks outgrow
//! the caches: a ray that passes a cell's box cannot meet its triangles in that cell, so the
//! walk gives the cell out with no blocks to test. A cell whose surface fills only a corner
//! of it is passed over without waiting for its blocks (a round trip to memory each, on a
//! mesh the size of the full dragon) or testing them.
//!
//! Each box holds the parts of the cell's triangles within the cell (grown by the build's
//! pad): a triangle inside the cell adds its bounds; one that crosses the cell's faces adds,
//! intersected over the crossed axes, the bounds of its part within each crossed axis's
//! slab (its corners inside and its edges' crossings of the slab's planes: exact for a
//! triangle that crosses the faces of one axis). The bounds are kept in 31sts of the cell,
//! rounded outwards, 5 bits a bound: a 32-bit word per occupied cell in an array beside the
//! cells' offsets ([`crate::accel::grid::storage::cells`]), whose first two lines a ray entering the macrocell
//! asks for with the record. The build finds each block's box as it writes the block, for
//! its eight triangles at once and without a branch ([`block_word`]), and joins a cell's;
//! the full dragon's build takes 0.11–0.13 s (0.10 s without boxes, Embree 0.16–0.17).
//! Nothing is lost that the walk needs: a hit on one of the cell's triangles outside the
//! cell lies in another cell along the ray, which holds the triangle too (the grid's exact
//! hit-in-cell rule), so answers are bit for bit those of the grid without boxes.
//!
//! On the full dragon, against the grid without boxes (`tools/dev/grid-ab.sh a75f5a5
//! dragon_vrip.ply.gz outside,camera,bounce,shadow,light 7`, identical answers), time of
//! outside / camera / bounce / shadow / light rays: 0.91 / 1.00 / 0.94 / 0.92 / 0.94 in
//! chunks of 10,000 rays, 0.93 / 0.98 / 0.95 / 0.95 / 0.93 in cache (`GRID_AB_CHUNK=250`).
//!
//! The walk tests the box as soon as it finds the cell, before it asks for the cell's
//! blocks, and without a branch on the outcome (a cell passed is given out with an empty
//! run of blocks): passing a cell by a branch, whose outcome is as good as random, cost the
//! 11k dragon 9–19 %, and asking for a passed cell's blocks anyway cost the full dragon 6 %
//! of its time in cache. Each grid's walk is compiled with or without the test
//! (`BOXED`), and grids whose blocks fit in the caches keep no boxes ([`BOXED_BLOCKS`]):
//! there a block costs no more than the test, and the 11k dragon lost 1–12 % with boxes
//! (measured at b0114e4; docs/design/grid.md).
//!
//! Grids whose blocks outgrow even the last-level cache ([`MASKED_BLOCKS_FROM`]) keep each
//! block's word too, and order the triangles of each cell of several blocks so that a
//! block's eight lie together ([`crate::accel::grid::build::block_order`]). When the walk finds such a cell
//! whose box the ray meets, it tests the boxes of its blocks ([`block_mask`]) and asks
//! memory for, and tests, only the blocks whose boxes the ray meets. Answers are again those of the grid without boxes, but for ties between equal
//! hits, which the order within a cell decides.

use std::ops::Range;

use glam::{IVec3, Vec3, Vec3A};

use crate::accel::Triangle;
use crate::accel::grid::frame::{CellWalk, GridFrame};
use crate::accel::grid::storage::block::{Block, LANES};
use crate::geometry::Aabb;

/// Grids whose blocks take more bytes than this keep a box per occupied cell: about half a
/// large last-level cache. The 203k dragon's 23 MB of blocks gain (outside rays 0.96 the
/// time, bounce 0.96, shadow 0.86; in cache 0.94, 0.95, 0.94), while the 47k dragon's
/// 6.5 MB and the 11k's 1.8 MB, which stay in the caches, lost 1–4 % even with the test
/// after their blocks were asked for.
pub(in crate::accel::grid) const BOXED_BLOCKS: usize = 16 << 20;

/// Steps per cell along each axis of a box's bounds (5 bits: 0 to 31).
const STEPS: f32 = 31.0;

/// Bits of one bound.
const BITS: u32 = 5;

/// The box word of a whole cell.
pub(in crate::accel::grid) const WHOLE: u32 = 0x3fff_8000;

/// The box word of nothing (lower bounds above upper ones), which [`join_all`] starts from.
const NOTHING: u32 = 0x7fff;

/// Grids whose blocks take more bytes than this keep a box per block as well, and test only
/// the blocks of a cell whose boxes the ray meets ([`block_mask`]): more than a large
/// last-level cache (32 MB on the development machine) holds. The full dragon's 89 MB of
/// blocks gain (outside rays 0.94 the time, bounce 0.93, shadow 0.97, camera and light
/// 1.04; in cache 1.03 / 1.09 / 1.07 / 1.00 / 1.00), while the 203k dragon's 23 MB lost
/// 1–10 % (in cache 7–11 %): where the blocks stay in the caches, the masks cost more than
/// the blocks they spare (measured at 6d13fe3).
pub(in crate::accel::grid) const MASKED_BLOCKS_FROM: usize = 48 << 20;

/// Which boxes a grid whose blocks take `block_bytes` keeps.
pub(in crate::accel::grid) fn boxes_for(block_bytes: usize) -> Kept {
    match block_bytes {
        b if b > MASKED_BLOCKS_FROM => Kept::CellsAndBlocks,
        b if b > BOXED_BLOCKS => Kept::Cells,
        _ => Kept::None,
    }
}

/// The boxes a grid keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::accel::grid) enum Kept {
    None,
    /// A box per occupied cell.
    Cells,
    /// A box per occupied cell and per block, with each crowded cell's triangles in Morton
    /// order ([`crate::accel::grid::build::block_order`]).
    CellsAndBlocks,
}

/// How far, in cells, each decoded box is grown: past the margin by which cells are grown
/// when they are filled ([`GridFrame::pad`], which the boxes are clipped to and which the
/// walk may land in by rounding) twice over, and never less than 1/128 cell (for the test's
/// own rounding). `None` when that is a quarter of a cell or more, where a box would seldom
/// pass anything (a grid far from its origin for its size).
pub(in crate::accel::grid) fn margin_for(frame: &GridFrame) -> Option<Vec3A> {
    let margin = (2.0 * frame.pad() * frame.inv_cell_size).max(Vec3::splat(1.0 / 128.0));
    (margin.max_element() < 0.25).then_some(margin.into())
}

/// One value per lane of a block.
type Lanes = [f32; LANES];

/// A point per lane of a block, axis by axis.
type LanePoints = [Lanes; 3];

/// The word of the box of the parts within cell `c` of `block`'s triangles: bit for bit
/// the word of [`CellBounds::part`] joined over them, found for the eight lanes at once
/// and without a branch. Found triangle by triangle, with a branch per crossed axis whose
/// outcome is as good as random, the box pass took 0.05 s of the full dragon's 0.15 s
/// build; this way it takes about 0.02 s.
#[inline(always)]
pub(in crate::accel::grid) fn block_word(frame: &GridFrame, c: IVec3, block: &Block) -> u32 {
    let cell = CellBounds::new(frame, c);
    let (corners, used) = block.corners();
    word(frame, &cell, cell.lanes_part(&corners, used))
}

/// The word of the box of the parts within cell `c` of `triangles`, found triangle by
/// triangle: what [`block_word`] must find for a block of them.
#[cfg(test)]
pub(in crate::accel::grid) fn triangles_word(
    frame: &GridFrame,
    c: IVec3,
    triangles: impl IntoIterator<Item = Triangle>,
) -> u32 {
    let cell = CellBounds::new(frame, c);
    let parts = triangles.into_iter().filter_map(|t| cell.part(&t));
    word(frame, &cell, parts.fold(Aabb::EMPTY, Aabb::union))
}

/// The word of `part`, a box within `cell` ([`NOTHING`] if it is empty). Inlined, so that
/// the block writer compiled for AVX2 rounds in one instruction rather than a call.
#[inline(always)]
fn word(frame: &GridFrame, cell: &CellBounds, part: Aabb) -> u32 {
    if part.min.cmpgt(part.max).any() {
        return NOTHING;
    }
    encode(
        (part.min - cell.corner) * frame.inv_cell_size,
        (part.max - cell.corner) * frame.inv_cell_size,
    )
}

/// The box word that holds the boxes `words` hold (those of one cell's blocks); a whole
/// cell if they hold nothing (rounding may clip away a triangle that touches the grown cell
/// only at a corner).
pub(in crate::accel::grid) fn join_all(words: &[u32]) -> u32 {
    let field = |word: u32, i: u32| (word >> (BITS * i)) & ((1 << BITS) - 1);
    let joined = words.iter().fold(NOTHING, |joined, &word| {
        (0..6).fold(0, |out, i| {
            let (a, b) = (field(joined, i), field(word, i));
            out | (if i < 3 { a.min(b) } else { a.max(b) }) << (BITS * i)
        })
    });
    if joined == NOTHING { WHOLE } else { joined }
}

/// A cell, grown by [`GridFrame::pad`] as the build grows cells when it fills them.
struct CellBounds {
    /// The cell's lower corner.
    corner: Vec3,
    /// The grown cell.
    from: Vec3,
    to: Vec3,
}

impl CellBounds {
    fn new(frame: &GridFrame, c: IVec3) -> CellBounds {
        let pad = frame.pad();
        let corner = frame.bounds.min + c.as_vec3() * frame.cell_size;
        CellBounds {
            corner,
            from: corner - pad,
            to: corner + frame.cell_size + pad,
        }
    }

    /// Bounds that hold the part of `triangle` within the cell (`None` if nothing of it is
    /// left).
    fn part(&self, triangle: &Triangle) -> Option<Aabb> {
        let (lo, hi) = self.part_bounds(triangle.vertices());
        lo.cmple(hi).all().then_some(Aabb { min: lo, max: hi })
    }

    /// [`CellBounds::part`] of each lane's triangle, whose corners `corners` holds (corner
    /// by corner), joined over the lanes `used`.
    #[inline(always)]
    fn lanes_part(&self, corners: &[LanePoints; 3], used: [bool; LANES]) -> Aabb {
        let mut lanes_lo = [[0.0; LANES]; 3];
        let mut lanes_hi = [[0.0; LANES]; 3];
        for l in 0..LANES {
            let corner = |k: usize| Vec3::new(corners[k][0][l], corners[k][1][l], corners[k][2][l]);
            let (lo, hi) = self.part_bounds([corner(0), corner(1), corner(2)]);
            let empty = !used[l] | (lo.x > hi.x) | (lo.y > hi.y) | (lo.z > hi.z);
            let lo = if empty { Vec3::INFINITY } else { lo };
            let hi = if empty { Vec3::NEG_INFINITY } else { hi };
            (lanes_lo[0][l], lanes_lo[1][l], lanes_lo[2][l]) = (lo.x, lo.y, lo.z);
            (lanes_hi[0][l], lanes_hi[1][l], lanes_hi[2][l]) = (hi.x, hi.y, hi.z);
        }
        let mut joined = Aabb::EMPTY;
        for l in 0..LANES {
            let lane = |m: &LanePoints| Vec3::new(m[0][l], m[1][l], m[2][l]);
            joined.min = least3(joined.min, lane(&lanes_lo));
            joined.max = greatest3(joined.max, lane(&lanes_hi));
        }
        joined
    }

    /// Bounds that hold the part within the cell of the triangle with corners `c` (lower
    /// above upper on some axis if nothing of it is left): on each axis, the bounds of the
    /// triangle's part within that axis's slab (its corners inside the slab and its edges'
    /// crossings of the slab's planes), intersected with each other and with the cell.
    /// Exact for a triangle that crosses the faces of one axis, as most do; for an axis
    /// whose faces it does not cross, that part is the whole triangle. Straight-line code
    /// on single numbers, with selections for branches (whose outcomes are as good as
    /// random), so that [`CellBounds::lanes_part`] runs eight triangles side by side in
    /// vector lanes.
    #[inline(always)]
    fn part_bounds(&self, c: [Vec3; 3]) -> (Vec3, Vec3) {
        let (from, to) = (self.from, self.to);
        let lo = greatest3(least3(least3(c[0], c[1]), c[2]), from);
        let hi = least3(greatest3(greatest3(c[0], c[1]), c[2]), to);
        let (x_lo, x_hi) = slab_part::<0>(c, from.x, to.x);
        let (y_lo, y_hi) = slab_part::<1>(c, from.y, to.y);
        let (z_lo, z_hi) = slab_part::<2>(c, from.z, to.z);
        (
            greatest3(greatest3(greatest3(lo, x_lo), y_lo), z_lo),
            least3(least3(least3(hi, x_hi), y_hi), z_hi),
        )
    }
}

/// The bounds of the part of the triangle with corners `c` within the slab `from ≤ p[AXIS]
/// ≤ to`: its corners inside the slab and its edges' crossings of the slab's planes.
#[inline(always)]
fn slab_part<const AXIS: usize>(c: [Vec3; 3], from: f32, to: f32) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let mut add = |p: Vec3, counts: bool| {
        lo = least3(lo, if counts { p } else { Vec3::INFINITY });
        hi = greatest3(hi, if counts { p } else { Vec3::NEG_INFINITY });
    };
    for (u, w) in [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])] {
        let (x, y) = (u[AXIS], w[AXIS]);
        add(u, (x >= from) & (x <= to));
        for plane in [from, to] {
            let (du, dw) = (x - plane, y - plane);
            let crossing = ((du < 0.0) != (dw < 0.0)) & (du != dw);
            add(u + (w - u) * (du / (du - dw)), crossing);
        }
    }
    (lo, hi)
}

/// [`least`] axis by axis.
#[inline(always)]
fn least3(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(least(a.x, b.x), least(a.y, b.y), least(a.z, b.z))
}

/// [`greatest`] axis by axis.
#[inline(always)]
fn greatest3(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(greatest(a.x, b.x), greatest(a.y, b.y), greatest(a.z, b.z))
}

/// The lesser of `a` and `b`: for numbers, [`f32::min`], but one vector instruction.
#[inline(always)]
fn least(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

/// The greater of `a` and `b`: for numbers, [`f32::max`], but one vector instruction.
#[inline(always)]
fn greatest(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

/// The word of the box from `lo` to `hi` (in cells from the cell's lower corner), each
/// bound clamped to the cell and rounded outwards to a 31st.
pub(in crate::accel::grid) fn encode(lo: Vec3, hi: Vec3) -> u32 {
    let lo = (lo.clamp(Vec3::ZERO, Vec3::ONE) * STEPS).floor().as_uvec3();
    let hi = (hi.clamp(Vec3::ZERO, Vec3::ONE) * STEPS)
        .ceil()
        .as_uvec3()
        .max(lo);
    let fields = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z];
    (0..6).fold(0, |word, i| word | fields[i] << (BITS * i as u32))
}

/// The bounds a box word holds, in 31sts of a cell from the cell's lower corner: lower,
/// upper.
#[inline(always)]
pub(in crate::accel::grid) fn decode<const FUSED: bool>(word: u32) -> (Vec3A, Vec3A) {
    #[cfg(target_arch = "x86_64")]
    if FUSED {
        use std::arch::x86_64::{
            _mm_and_si128, _mm_cvtepi32_ps, _mm_set1_epi32, _mm_setr_epi32, _mm_srlv_epi32,
        };
        // SAFETY: `FUSED` code is compiled for, and runs only on, processors with AVX2 and
        // FMA ([`crate::accel::isa::x86_level`]), and `_mm_srlv_epi32` is AVX2.
        let (lo, hi) = unsafe {
            let w = _mm_set1_epi32(word as i32);
            let field = _mm_set1_epi32((1 << BITS) - 1);
            let lo = _mm_and_si128(_mm_srlv_epi32(w, _mm_setr_epi32(0, 5, 10, 0)), field);
            let hi = _mm_and_si128(_mm_srlv_epi32(w, _mm_setr_epi32(15, 20, 25, 15)), field);
            (_mm_cvtepi32_ps(lo), _mm_cvtepi32_ps(hi))
        };
        return (Vec3A::from(lo), Vec3A::from(hi));
    }
    let field = |i: u32| ((word >> (BITS * i)) & ((1 << BITS) - 1)) as f32;
    (
        Vec3A::new(field(0), field(1), field(2)),
        Vec3A::new(field(3), field(4), field(5)),
    )
}

/// True unless the walk's ray passes the box `word` of its current cell, grown by
/// `margin` cells ([`margin_for`]).
#[inline(always)]
pub(in crate::accel::grid) fn meets<const FUSED: bool>(
    walk: &CellWalk<FUSED>,
    word: u32,
    margin: Vec3A,
) -> bool {
    let (lo, hi) = decode::<FUSED>(word);
    walk.meets_box(lo, hi, 1.0 / STEPS, margin)
}

/// Which of the blocks `blocks` the walk's ray may meet, from their box words in `words`
/// (one per block, [`block_word`]): bit `i` is set unless the ray passes the box of the
/// range's `i`-th block. Only the first [`MASKED_BLOCKS`] blocks have bits; the walk tests
/// any beyond them. One box at a time: eight at once in vector lanes, with the words
/// decoded lane by lane, took 1.04–1.06 the time of this on the full dragon's outside,
/// bounce and light rays (measured at 6d13fe3).
#[inline(always)]
pub(in crate::accel::grid) fn block_mask<const FUSED: bool>(
    walk: &CellWalk<FUSED>,
    words: &[u32],
    blocks: Range<usize>,
    margin: Vec3A,
) -> u64 {
    let count = blocks.len().min(MASKED_BLOCKS);
    let mut mask = 0;
    for i in 0..count {
        mask |= u64::from(meets(walk, words[blocks.start + i], margin)) << i;
    }
    mask
}

/// Blocks of a cell that [`block_mask`] answers for.
pub(in crate::accel::grid) const MASKED_BLOCKS: usize = 64;

/// True when the box `word` of cell `c`, grown by `margin`, holds every point of
/// `triangle` within the cell grown by [`GridFrame::pad`]: what the walk relies on
/// ([`crate::accel::grid::Grid::validate`]).
pub(in crate::accel::grid) fn holds(
    frame: &GridFrame,
    c: IVec3,
    word: u32,
    margin: Vec3A,
    triangle: &Triangle,
) -> bool {
    let cell = CellBounds::new(frame, c);
    let Some(bounds) = cell.part(triangle) else {
        return true;
    };
    let (lo, hi) = decode::<false>(word);
    let (lo, hi) = (
        Vec3::from(lo / STEPS - margin),
        Vec3::from(hi / STEPS + margin),
    );
    let (part_lo, part_hi) = (
        (bounds.min - cell.corner) * frame.inv_cell_size,
        (bounds.max - cell.corner) * frame.inv_cell_size,
    );
    part_lo.cmpge(lo).all() && part_hi.cmple(hi).all()
}

#[cfg(test)]
mod tests {
    use glam::UVec3;

    use super::*;
    use crate::accel::isa::{Kernel, X86Level, dispatch};

    /// A triangle's part within a cell holds every point of the triangle within the cell
    /// (grown by the pad), and is often smaller than the triangle's bounds clamped to the
    /// cell.
    #[test]
    fn a_part_holds_every_point_of_the_triangle_within_the_cell() {
        let bounds = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let frame = GridFrame::new(bounds, UVec3::splat(4));
        let mut rng = crate::render::sampling::Rng::new(53, 1);
        let (mut met, mut tighter, mut points) = (0, 0, 0);
        for k in 0..3_000 {
            let mut u = || rng.uniform();
            let size = [0.2, 0.6, 1.5][k % 3];
            let a = Vec3::new(u(), u(), u()) * 2.0 - 1.0;
            let mut corner = || a + (Vec3::new(u(), u(), u()) - 0.5) * size;
            let triangle = Triangle::new(a, corner(), corner());
            // The cell of the triangle's first corner.
            let cell = CellBounds::new(&frame, frame.cell_of(a).as_ivec3());
            let part = cell.part(&triangle);
            for _ in 0..200 {
                let (s, t) = (u(), u());
                let (s, t) = if s + t > 1.0 {
                    (1.0 - s, 1.0 - t)
                } else {
                    (s, t)
                };
                let p = triangle.v0 + triangle.e1 * s + triangle.e2 * t;
                if p.cmpge(cell.from).all() && p.cmple(cell.to).all() {
                    let part = part.expect("a part where the triangle meets the cell");
                    let slack = Vec3::splat(1e-5);
                    assert!(p.cmpge(part.min - slack).all() && p.cmple(part.max + slack).all());
                    points += 1;
                }
            }
            if let Some(part) = part {
                let b = triangle.bounds();
                let (lo, hi) = (b.min.max(cell.from), b.max.min(cell.to));
                assert!(part.min.cmpge(lo).all() && part.max.cmple(hi).all());
                met += 1;
                tighter += usize::from(
                    (part.max - part.min).element_product() < 0.9 * (hi - lo).element_product(),
                );
            }
        }
        assert!(points > 10_000, "{points} points");
        assert!(
            tighter * 4 > met,
            "{tighter} of {met} parts tighter than the bounds"
        );
    }

    /// A box word holds bounds that contain the box encoded, clamped to the cell, and no
    /// more than a 31st wider on each side.
    #[test]
    fn a_word_holds_the_box_rounded_outwards() {
        let mut rng = crate::render::sampling::Rng::new(41, 0);
        for _ in 0..10_000 {
            let mut u = || rng.uniform() * 1.2 - 0.1;
            let (a, b) = (Vec3::new(u(), u(), u()), Vec3::new(u(), u(), u()));
            let (lo, hi) = (a.min(b), a.max(b));
            let word = encode(lo, hi);
            assert_eq!(word >> 30, 0);
            for (lo_d, hi_d) in [decode::<false>(word), decode_fast(word)] {
                let (lo_d, hi_d) = (lo_d / STEPS, hi_d / STEPS);
                let (lo_c, hi_c) = (
                    lo.clamp(Vec3::ZERO, Vec3::ONE),
                    hi.clamp(Vec3::ZERO, Vec3::ONE),
                );
                assert!(Vec3::from(lo_d).cmple(lo_c).all(), "{lo} {lo_d}");
                assert!(Vec3::from(hi_d).cmpge(hi_c).all(), "{hi} {hi_d}");
                assert!((lo_c - Vec3::from(lo_d)).max_element() <= 1.0 / STEPS + 1e-6);
                assert!((Vec3::from(hi_d) - hi_c).max_element() <= 1.0 / STEPS + 1e-6);
            }
        }
        assert_eq!(decode::<false>(WHOLE), (Vec3A::ZERO, Vec3A::splat(STEPS)));
        assert_eq!(encode(Vec3::splat(-1.0), Vec3::splat(2.0)), WHOLE);
    }

    /// A box word's decoding as a [`Kernel`].
    struct Decode(u32);

    impl Kernel for Decode {
        type Output = (Vec3A, Vec3A);
        fn run<const FUSED: bool>(self) -> (Vec3A, Vec3A) {
            decode::<FUSED>(self.0)
        }
    }

    /// The AVX2 decoding (with fused multiply-adds) where the processor has it, else the
    /// portable one.
    fn decode_fast(word: u32) -> (Vec3A, Vec3A) {
        dispatch(X86Level::Avx2, Decode(word))
    }
}
