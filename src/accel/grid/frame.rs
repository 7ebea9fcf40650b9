//! What every uniform grid here shares, over triangles or over instances: a box cut into
//! near-cubic cells, the cell under a point, and the 3D-DDA walk of Amanatides & Woo (1987),
//! "A fast voxel traversal algorithm for ray tracing", through the cells a ray crosses.

use glam::{BVec3A, IVec3, UVec3, Vec3, Vec3A, Vec3Swizzles};

use super::cell_lanes::CellLanes;
use crate::accel::Ray;
use crate::geometry::Aabb;

/// Most cells along one axis.
pub(crate) const MAX_RESOLUTION: u32 = 2048;
/// Most cells in one grid (per-cell build counters would otherwise be absurd).
pub(crate) const MAX_CELLS: u64 = 1 << 28;

/// An axis along which the ray's direction is below this fraction of its largest
/// component counts as parallel: over the ray's reach along the largest axis it moves by
/// far less than rounding, and its face distances `slope·k + offset` stay far from
/// overflow.
const PARALLEL_FRACTION: f32 = 1e-20;

/// A box tiled by `resolution` equal cells, numbered x fastest, then y, then z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct GridFrame {
    /// The box the cells tile.
    pub bounds: Aabb,
    /// Cells per axis.
    pub resolution: UVec3,
    /// Size of one cell per axis.
    pub cell_size: Vec3,
    /// `1 / cell_size`.
    pub inv_cell_size: Vec3,
}

impl GridFrame {
    /// `bounds` cut into `resolution` cells.
    pub fn new(bounds: Aabb, resolution: UVec3) -> GridFrame {
        let cell_size = bounds.extent() / resolution.as_vec3();
        GridFrame {
            bounds,
            resolution,
            cell_size,
            inv_cell_size: cell_size.recip(),
        }
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.resolution.x as usize * self.resolution.y as usize * self.resolution.z as usize
    }

    /// Index of cell `c`.
    #[inline]
    pub fn cell_index(&self, c: UVec3) -> usize {
        (c.x + self.resolution.x * (c.y + self.resolution.y * c.z)) as usize
    }

    /// The cell holding point `p`, clamped into the grid.
    #[inline(always)]
    pub fn cell_of(&self, p: Vec3) -> UVec3 {
        let c = ((p - self.bounds.min) * self.inv_cell_size).floor();
        c.max(Vec3::ZERO).as_uvec3().min(self.resolution - 1)
    }

    /// How far cells are grown when deciding what they hold, so that rounding never drops
    /// a cell something touches: whatever lies on a cell face belongs to both sides.
    #[inline(always)]
    pub fn pad(&self) -> Vec3 {
        let magnitude = self
            .bounds
            .min
            .abs()
            .max(self.bounds.max.abs())
            .max_element();
        self.cell_size * 1e-4 + Vec3::splat(magnitude * 1e-6)
    }

    /// The cells (inclusive corners) a box touches, cells grown by [`GridFrame::pad`].
    #[inline(always)]
    pub fn cells_of_box(&self, b: &Aabb) -> (UVec3, UVec3) {
        let pad = self.pad();
        (self.cell_of(b.min - pad), self.cell_of(b.max + pad))
    }

    /// The part of `ray` within the box: where it enters and leaves it, within the ray's
    /// own extent, with what the walk's start needs; `None` when it misses the box. In
    /// vector lanes, with no `f32::min`/`max` (whose NaN handling costs more than the
    /// rest): lanes that could be NaN are chosen away first.
    #[inline(always)]
    fn clip(&self, ray: &Ray) -> Option<Clip> {
        let origin = Vec3A::from(ray.origin);
        let direction = Vec3A::from(ray.direction);
        if !(origin.is_finite() && direction.is_finite()) {
            return None;
        }
        let inv = direction.recip();
        // An axis the ray is parallel to (or nearly: `PARALLEL_FRACTION`, or 1/d overflows)
        // does not move:
        // slope 0 and offset ∞ put its faces at ∞, and its slab holds the whole ray or none
        // of it (0·∞ would be NaN for an origin on one of its planes).
        let magnitude = direction.abs();
        let moving = magnitude.cmpgt(Vec3A::splat(magnitude.max_element() * PARALLEL_FRACTION))
            & inv.abs().cmplt(Vec3A::INFINITY);
        let (lo, hi) = (Vec3A::from(self.bounds.min), Vec3A::from(self.bounds.max));
        let t0 = (lo - origin) * inv;
        let t1 = (hi - origin) * inv;
        let inside = origin.cmpgt(lo) & origin.cmplt(hi);
        let (all, none) = (Vec3A::NEG_INFINITY, Vec3A::INFINITY);
        let near = Vec3A::select(moving, t0.min(t1), Vec3A::select(inside, all, none));
        // Widen each slab's exit by its rounding error, so a ray through the box is never
        // clipped away by rounding (pbrt-v4 §6.8.2: t_far·(1 + 2γ(3))).
        let far = Vec3A::select(
            moving,
            t0.max(t1) * (1.0 + 2.0 * crate::accel::SLAB_ROUNDING),
            Vec3A::select(inside, none, all),
        );
        let t_start = near.max_element().max(ray.t_min);
        let t_end = far.min_element().min(ray.t_max);
        // Written so that a NaN bound also counts as a miss.
        if t_start > t_end || t_start.is_nan() || t_end.is_nan() {
            return None;
        }
        Some(Clip {
            origin,
            direction,
            inv,
            moving,
            inside,
            t0,
            t_start,
            t_end,
        })
    }

    /// The part of `ray` within the box, reversed: from the point where the ray leaves the
    /// box (or ends) back to where it enters it (or starts), with its extent lengthened by
    /// a ten-thousandth. A walk along it visits, in the opposite order, the cells a walk
    /// along `ray` visits: both start points lie within a few rounding errors of the true
    /// ones, far inside the margin by which cells are grown when they are filled
    /// ([`GridFrame::pad`]). `None` when the ray misses the box (a walk along `ray` finds
    /// no cell either) or has no finite end within it (a direction of no length). For
    /// shadow queries, whose answer does not depend on the order of the cells.
    #[inline(always)]
    pub fn reversed(&self, ray: &Ray) -> Option<Ray> {
        let clip = self.clip(ray)?;
        let end = ray.at(clip.t_end);
        end.is_finite().then(|| Ray {
            origin: end,
            direction: -ray.direction,
            t_min: 0.0,
            t_max: (clip.t_end - clip.t_start) * 1.0001,
            time: ray.time,
        })
    }

    /// Clips the ray to the box and finds the first cell; `None` when it misses the box.
    /// Inlined, so that it is compiled with the caller's instruction set; `FUSED` as in
    /// [`CellWalk`].
    #[inline(always)]
    pub fn start_walk<const FUSED: bool>(&self, ray: &Ray) -> Option<CellWalk<FUSED>> {
        #[cfg(target_arch = "x86_64")]
        debug_assert!(
            !FUSED || std::is_x86_feature_detected!("fma"),
            "a fused walk on a processor without FMA"
        );
        let clip = self.clip(ray)?;
        let (origin, direction, moving) = (clip.origin, clip.direction, clip.moving);
        let lo = Vec3A::from(self.bounds.min);
        let resolution_f = self.resolution.as_vec3a();
        let at = origin + direction * clip.t_start;
        let cell_f = truncate(
            ((at - lo) * Vec3A::from(self.inv_cell_size))
                .max(Vec3A::ZERO)
                .min(resolution_f - Vec3A::ONE),
        );
        let up = moving & direction.cmpgt(Vec3A::ZERO);
        let step_f = Vec3A::select(
            up,
            Vec3A::ONE,
            Vec3A::select(moving, Vec3A::NEG_ONE, Vec3A::ZERO),
        );
        let cells_per_t = Vec3A::select(
            moving,
            direction * Vec3A::from(self.inv_cell_size),
            Vec3A::ZERO,
        );
        let slope = Vec3A::select(moving, Vec3A::from(self.cell_size) * clip.inv, Vec3A::ZERO);
        let offset = Vec3A::select(moving, clip.t0, Vec3A::INFINITY);
        let mut walk = CellWalk {
            cell: CellLanes::truncating(cell_f),
            step: CellLanes::truncating(step_f),
            step_f,
            face: Vec3A::ZERO,
            slope,
            offset,
            t_next: Vec3A::INFINITY,
            t_end: clip.t_end,
            from_outside: !clip.inside.all(),
            cells_per_t,
            cells_at_zero: Vec3A::select(moving, -offset * cells_per_t, cell_f + Vec3A::splat(0.5)),
            up: Vec3A::select(up, Vec3A::ONE, Vec3A::ZERO),
            resolution_f,
            t_per_cell: slope * step_f,
        };
        walk.face = cell_f + walk.up;
        walk.t_next = mul_add::<FUSED>(walk.slope, walk.face, walk.offset);
        Some(walk)
    }
}

/// A ray clipped to a grid's box ([`GridFrame::clip`]).
#[derive(Clone, Copy)]
struct Clip {
    origin: Vec3A,
    direction: Vec3A,
    /// `1 / direction`.
    inv: Vec3A,
    /// The axes the ray moves along (not parallel to).
    moving: BVec3A,
    /// The axes whose slab holds the origin strictly inside.
    inside: BVec3A,
    /// Where the ray crosses the box's lower face on each axis.
    t0: Vec3A,
    /// The ray's parameters where it enters and leaves the box, within its extent.
    t_start: f32,
    t_end: f32,
}

/// The walk of one ray through the cells it crosses, front to back.
///
/// Written without branches on the axis (the axis of each step is as good as random for
/// bounce rays, so a branch on it would be mispredicted about every other step) and
/// without indexing vectors by a run-time axis, so the state stays in registers. With
/// `FUSED`, its multiply-adds are fused ([`mul_add`]): only in code compiled for
/// processors with FMA, which the caller has checked.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellWalk<const FUSED: bool = false> {
    /// Current cell, in integer lanes: the next step's lookup starts from it
    /// ([`CellLanes`]).
    cell: CellLanes,
    /// −1, 0 or +1 per axis.
    step: CellLanes,
    /// `step` as floats.
    step_f: Vec3A,
    /// The current cell's far face per axis, `cell + up`, as floats (whole numbers,
    /// so exact): a plain step adds to it and the exit distances follow in one
    /// multiply-add, without an integer-to-float conversion in the chain from one step to
    /// the next (a leap converts its landing cell, beside the lookup that follows).
    face: Vec3A,
    /// The ray crosses the plane of cell face `k` on axis `a` at `t = slope[a]·k + offset[a]`
    /// (∞ for an axis the ray is parallel to): face distances come from whole-number face
    /// coordinates, so no error accumulates.
    slope: Vec3A,
    offset: Vec3A,
    /// Ray parameter at which the ray leaves the current cell, per axis.
    t_next: Vec3A,
    /// Ray parameter at which the ray leaves the grid (or reaches `t_max`).
    pub t_end: f32,
    /// True when the ray starts outside the grid's box (or on its boundary).
    pub from_outside: bool,
    /// Cells crossed per unit of `t` on each axis (0 for an axis the ray is parallel to):
    /// the cell coordinate at `t` is `(t − offset)·cells_per_t`.
    cells_per_t: Vec3A,
    /// The cell coordinate at `t = 0`, `−offset·cells_per_t`, so the coordinate at `t` is
    /// one multiply-add; on an axis the ray is parallel to, the middle of its cells' slab.
    cells_at_zero: Vec3A,
    /// 1 on axes the ray moves up, else 0: the cell's far face is `cell + up`.
    up: Vec3A,
    /// `resolution` as floats.
    resolution_f: Vec3A,
    /// How much later the ray crosses a face one cell further along each axis
    /// (`slope·step`, ≥ 0; 0 for an axis the ray is parallel to).
    t_per_cell: Vec3A,
}

impl<const FUSED: bool> CellWalk<FUSED> {
    /// Moves the walk out of the empty cube of `side` cells a side (`side` ≥ `2^unit_shift`)
    /// that has the current cell's unit of `2^unit_shift` cells a side (units aligned to
    /// multiples of their size) in its corner and extends in the ray's direction, to the
    /// first cell beyond it along the ray;
    /// false when the ray leaves the grid or ends first. On the axes it does not leave the
    /// cube by, the walk lands in the cell under the exit point, kept within the cube and
    /// never behind its current cell, so rounding cannot move it backwards or sideways. In
    /// vector lanes and whole-number floats (exact up to 2²⁴ cells), branch-free on the
    /// exit axis like [`CellWalk::advance`].
    #[inline(always)]
    pub fn leave_cube(&mut self, side: f32, unit_shift: u32) -> bool {
        self.leave_box(Vec3A::splat(side), unit_shift)
    }

    /// [`CellWalk::leave_cube`] for a box of `reach` cells along each axis (each at least
    /// `2^unit_shift`).
    #[inline(always)]
    pub fn leave_box(&mut self, reach: Vec3A, unit_shift: u32) -> bool {
        let unit = (1 << unit_shift) as f32;
        let cell = self.face - self.up;
        // The cube's corner unit, from the integer cell (for cubes of cells, the cell).
        let base = if unit_shift == 0 {
            cell
        } else {
            self.cell.round_down(unit_shift).to_floats()
        };
        // The cube's far faces: `side` cells past `base` upwards, or `side` cells below the
        // unit's top face downwards (`base + unit − side`); within the grid.
        let corner = base + (Vec3A::ONE - self.up) * unit;
        let far = (self.step_f * reach + corner).clamp(Vec3A::ZERO, self.resolution_f);
        // Where the ray crosses them: `slope·far + offset`, expanded so that the reach,
        // the last value to arrive, enters in one multiply-add (for a cube of cells, the
        // rest is the current cell's exit distances one cell back). Not clamped to the
        // grid: where a face lies beyond it, the ray leaves the grid first, at `t_end` or
        // within its rounding, and the checks below end the walk (or land it in the
        // cube's last cell). Rounding may differ from `slope·far + offset` by a few ulps,
        // as any two roundings of a tie do; the landing cell is kept within the cube or
        // on the exit axis just beyond it either way.
        let at_corner = if unit_shift == 0 {
            self.t_next - self.t_per_cell
        } else {
            self.slope * corner + self.offset
        };
        let t_far = mul_add::<FUSED>(self.t_per_cell, reach, at_corner);
        let (t_exit, chosen) = first_exit(t_far);
        // The cube's last cells (`far − 1` upwards, `far` downwards), and the cell beyond
        // on the exit axis (`far` upwards, `far − 1` downwards).
        let last = far - self.up;
        let next = far + self.up - Vec3A::ONE;
        let beyond = next.cmplt(Vec3A::ZERO) | next.cmpge(self.resolution_f);
        // (No axis chosen only if a distance is NaN, which the parallel axes' handling
        // rules out; the walk then ends rather than stand still.)
        if (t_exit.x >= self.t_end) | (beyond & chosen).any() | !chosen.any() {
            return false;
        }
        // The cell under the exit point on the other axes (on an axis the ray is parallel
        // to, its own cell: `cells_at_zero` holds it there and `cells_per_t` is 0), kept
        // within the cube and never behind the current cell; truncated, then clamped and
        // chosen in integer lanes (one conversion and three one-cycle operations on the way
        // to the next lookup). A NaN or out-of-range coordinate (which a point of the ray
        // within the grid does not have) truncates to `i32::MIN` on x86-64 (elsewhere `as`
        // saturates), so the clamp puts it on one of the cube's sides; the walk goes on
        // from there.
        let under = CellLanes::truncating(mul_add::<FUSED>(
            self.cells_per_t,
            t_exit,
            self.cells_at_zero,
        ));
        let (lo, hi) = (cell.min(last), cell.max(last));
        let side_cell = under.clamp(CellLanes::truncating(lo), CellLanes::truncating(hi));
        self.cell = CellLanes::select(chosen, CellLanes::truncating(next), side_cell);
        self.face = self.cell.to_floats() + self.up;
        self.t_next = mul_add::<FUSED>(self.slope, self.face, self.offset);
        true
    }

    /// Leaves the current cell: returns the largest ray parameter whose hits belong to it
    /// (`t_end` in the last cell), and moves on to the next cell; false as second value
    /// when there is none (the ray leaves the grid or reaches its end here).
    #[inline(always)]
    pub fn advance(&mut self) -> (f32, bool) {
        let (t_exit, axis) = first_exit(self.t_next);
        // One cell on along the exit axis.
        let moved = Vec3A::select(axis, self.step_f, Vec3A::ZERO);
        let next = self.face - self.up + moved;
        // Outside on that axis, or a face at or past the end: this cell was the last.
        let outside = next.cmplt(Vec3A::ZERO) | next.cmpge(self.resolution_f);
        if outside.any() | (t_exit.x >= self.t_end) | !axis.any() {
            return (self.t_end, false);
        }
        self.cell = self
            .cell
            .add(CellLanes::select(axis, self.step, CellLanes::zero()));
        self.face += moved;
        self.t_next = mul_add::<FUSED>(self.slope, self.face, self.offset);
        (t_exit.x, true)
    }

    /// True unless the ray, before its end, passes the box of the current cell from
    /// `lo·step − margin` to `hi·step + margin`, in cells from the cell's lower corner (a
    /// slab test, Kay & Kajiya 1986, on the walk's face distances: the box's faces are
    /// crossed at `slope·(cell + lo·step − margin) + offset`). An axis the ray is parallel
    /// to does not bound it.
    #[inline(always)]
    pub fn meets_box(&self, lo: Vec3A, hi: Vec3A, step: f32, margin: Vec3A) -> bool {
        let cell = self.face - self.up;
        let step = Vec3A::splat(step);
        let lo = mul_add::<FUSED>(lo, step, cell - margin);
        let hi = mul_add::<FUSED>(hi, step, cell + margin);
        let t_lo = mul_add::<FUSED>(self.slope, lo, self.offset);
        let t_hi = mul_add::<FUSED>(self.slope, hi, self.offset);
        let moving = self.slope.cmpne(Vec3A::ZERO);
        let near = Vec3A::select(moving, t_lo.min(t_hi), Vec3A::NEG_INFINITY).max_element();
        let far = Vec3A::select(moving, t_lo.max(t_hi), Vec3A::INFINITY).min_element();
        // Written so that a NaN distance counts as meeting the box.
        !(near > far || near > self.t_end)
    }

    /// The current cell.
    #[inline(always)]
    pub fn cell(&self) -> IVec3 {
        self.cell.ivec3()
    }

    /// −1, 0 or +1 per axis: the direction the walk moves along each.
    #[inline(always)]
    pub fn step(&self) -> IVec3 {
        self.step.ivec3()
    }
}

/// Where a ray first reaches one of the faces it crosses at `t` (per axis; in every lane),
/// and on which axis, as a lane mask (x before y before z on ties, so a walk never moves on
/// two axes at once). The mask comes from comparing the lanes with their rotations, in
/// parallel with the least distance rather than after it (the walk's steps are one chain of
/// dependent operations, so its length is what a step costs).
#[inline(always)]
fn first_exit(t: Vec3A) -> (Vec3A, BVec3A) {
    let (next, after) = (t.yzx(), t.zxy());
    // Per lane: at or before the next lane, strictly before it, at or before the lane
    // after, strictly before it — x wins if t.x ≤ t.y and t.x ≤ t.z, y if t.y ≤ t.z and
    // t.y < t.x, z if t.z < t.x and t.z < t.y.
    let (le_next, lt_next) = (t.cmple(next), t.cmplt(next));
    let (le_after, lt_after) = (t.cmple(after), t.cmplt(after));
    let x = BVec3A::new(true, false, false);
    let y = BVec3A::new(false, true, false);
    let first =
        (x & le_next & le_after) | (y & le_next & lt_after) | (!(x | y) & lt_next & lt_after);
    // The least lane in every lane, from the same rotations: no broadcast after it.
    (t.min(next).min(after), first)
}

/// `a·b + c` in each lane: with `FUSED`, one fused multiply-add (rounded once, and a step
/// shorter on the walk's chain of dependent operations: the warm queries of the full dragon
/// 0.97–0.99 the time, `tools/dev/grid-ab.sh` with `GRID_AB_CHUNK=250`), else a multiply and an
/// add. `FUSED` is set only by the grid's queries compiled with the `fma` feature, chosen
/// at run time on processors that have it ([`crate::accel::isa::x86_level`]); elsewhere it
/// is false.
#[inline(always)]
fn mul_add<const FUSED: bool>(a: Vec3A, b: Vec3A, c: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    if FUSED {
        use std::arch::x86_64::{__m128, _mm_fmadd_ps};
        // SAFETY: `FUSED` is true only in the queries compiled for FMA, which run only on
        // processors that have it (see above; debug builds check it in `start_walk`).
        return Vec3A::from(unsafe {
            _mm_fmadd_ps(__m128::from(a), __m128::from(b), __m128::from(c))
        });
    }
    a * b + c
}

/// `v` rounded towards zero (as whole-number floats): `floor` for the non-negative
/// coordinates of a walk, in two instructions where glam's `floor` takes nine.
#[inline(always)]
fn truncate(v: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128, _mm_cvtepi32_ps, _mm_cvttps_epi32};
        // SAFETY: SSE2, which these intrinsics need, is part of x86_64.
        Vec3A::from(unsafe { _mm_cvtepi32_ps(_mm_cvttps_epi32(__m128::from(v))) })
    }
    #[cfg(not(target_arch = "x86_64"))]
    v.trunc()
}

/// The box grown by a small fraction of its size, so flat contents get a volume and nothing
/// lies exactly on the boundary.
pub(crate) fn padded(b: Aabb) -> Aabb {
    let e = b.extent();
    let pad = Vec3::splat(
        e.max_element() * 1e-5
            + 1e-7 * b.min.abs().max(b.max.abs()).max_element()
            + f32::MIN_POSITIVE,
    );
    Aabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}

/// Cells per axis after Cleary & Wyvill (1988): R_a = d_a · ∛(λN / V), which makes cells
/// near-cubic. In V, thin axes count as at least the cube-root cell size of the longest
/// axis, so that flat contents (a wall, a floor, objects on a plane) get about λN cells in
/// their plane and one across it, instead of a vast number of slivers.
pub(crate) fn resolution(extent: Vec3, items: usize, density: f32) -> UVec3 {
    let target = (density * items as f32).max(1.0);
    let floor = extent.max_element() / target.cbrt();
    let e = extent.max(Vec3::splat(floor));
    let k = (target / (e.x * e.y * e.z)).cbrt();
    let mut r = (extent * k)
        .floor()
        .max(Vec3::ONE)
        .min(Vec3::splat(MAX_RESOLUTION as f32))
        .as_uvec3();
    while r.x as u64 * r.y as u64 * r.z as u64 > MAX_CELLS {
        r = (r.as_vec3() * 0.9).max(Vec3::ONE).as_uvec3();
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_follows_density_and_aspect() {
        let r = resolution(Vec3::new(2.0, 1.0, 1.0), 1000, 5.0);
        let cells = r.x * r.y * r.z;
        assert!((2500..=5000).contains(&cells), "{r}");
        assert!(r.x >= 2 * r.y - 1, "{r}");
    }

    #[test]
    fn flat_contents_get_few_cells() {
        let r = resolution(Vec3::new(2.0, 1e-5, 2.0), 2, 5.0);
        assert_eq!(r.y, 1);
        assert!(r.x * r.z <= 16, "{r}");
        let r = resolution(Vec3::new(2.0, 4e-5, 2.0), 800, 5.0);
        assert_eq!(r.y, 1, "{r}");
        assert!((1000..=4000).contains(&(r.x * r.z)), "{r}");
    }

    #[test]
    fn a_walk_visits_the_cells_a_diagonal_ray_crosses_in_order() {
        let frame = GridFrame::new(
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::splat(4.0),
            },
            UVec3::splat(4),
        );
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::new(1.0, 0.0, 0.0));
        let mut walk = frame.start_walk::<false>(&ray).unwrap();
        let mut cells = vec![walk.cell()];
        loop {
            let x = walk.cell().x;
            let (t, more) = walk.advance();
            if !more {
                assert_eq!(t, walk.t_end);
                break;
            }
            assert_eq!(t, (x + 2) as f32);
            cells.push(walk.cell());
        }
        assert_eq!(
            cells,
            (0..4).map(|x| IVec3::new(x, 0, 0)).collect::<Vec<_>>()
        );
    }

    /// Leaving a cube in one step lands where the plain 3D-DDA, stepping cell by cell,
    /// first leaves it (or both find the ray ends first), for cubes of cells and of
    /// macrocells, cubes of any side in cells with a macrocell in their corner, and boxes
    /// of a different side along each axis with a macrocell in their corner
    /// ([`CellWalk::leave_box`]); rays from inside the grid in every direction,
    /// axis-parallel ones included. Where the exit point lies within rounding of a face on
    /// another axis, the two may break the tie differently; such rays must be rare.
    #[test]
    fn leaving_a_cube_lands_where_the_cell_walk_leaves_it() {
        let resolution = UVec3::new(40, 24, 33);
        let frame = GridFrame::new(
            Aabb {
                min: Vec3::new(-1.0, 2.0, 0.5),
                max: Vec3::new(-1.0, 2.0, 0.5) + resolution.as_vec3() * 0.25,
            },
            resolution,
        );
        let mut rng = crate::render::sampling::Rng::new(17, 3);
        let (mut agreed, mut ties) = (0, 0);
        for k in 0..20_000 {
            let mut u = || rng.uniform();
            let origin = frame.bounds.min + Vec3::new(u(), u(), u()) * frame.bounds.extent();
            let mut direction = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5);
            if k % 10 == 0 {
                direction[k / 10 % 3] = 0.0;
            }
            let ray = Ray::new(origin, direction.normalize());
            let Some(start) = frame.start_walk::<false>(&ray) else {
                continue;
            };
            let unit = if k % 2 == 0 { 1 } else { 8 };
            // In cells: whole units, and (for units of 8) any side from one unit up.
            let side = match k / 2 % 6 {
                n @ 0..4 => (1 + n as i32) * unit,
                _ => unit + (k / 12 % 24) as i32,
            };
            // Every fourth ray of a macrocell: a box, each side from one unit up.
            let boxed = k % 8 == 1;
            let side = if boxed {
                IVec3::new(0, 1, 2).map(|a| unit + ((k as i32 / 8 * 7 + a * 5) % 29))
            } else {
                IVec3::splat(side)
            };
            let base = start.cell().div_euclid(IVec3::splat(unit)) * unit;
            let (lo, hi) = (
                IVec3::select(start.step().cmpgt(IVec3::ZERO), base, base + unit - side),
                IVec3::select(
                    start.step().cmpgt(IVec3::ZERO),
                    base + side - 1,
                    base + unit - 1,
                ),
            );
            let mut cell_walk = start;
            let expected = loop {
                if !cell_walk.advance().1 {
                    break None;
                }
                let c = cell_walk.cell();
                if c.cmplt(lo).any() || c.cmpgt(hi).any() {
                    break Some(c);
                }
            };
            let mut leap = start;
            let got = if boxed {
                leap.leave_box(side.as_vec3a(), unit.trailing_zeros())
            } else {
                leap.leave_cube(side.x as f32, unit.trailing_zeros())
            }
            .then_some(leap.cell());
            if got == expected {
                agreed += 1;
                continue;
            }
            // A tie: the landing cell differs from the walk's by one on some axis, at a
            // point within rounding of the face between them.
            let (Some(g), Some(e)) = (got, expected) else {
                panic!("ray {k}: leap {got:?}, walk {expected:?}");
            };
            assert!(
                (g - e).abs().max_element() <= 1,
                "ray {k}: leap {g}, walk {e}"
            );
            ties += 1;
        }
        assert!(agreed > 15_000, "{agreed} rays agreed");
        assert!(
            ties * 1000 <= agreed,
            "{ties} ties against {agreed} agreements"
        );
    }
}
