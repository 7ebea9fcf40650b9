//! The cells of one macrocell that a stretch of a ray can touch, as a mask in the layout of
//! the macrocell's occupancy record (bit `x + 8y` of word `z`), so that "does the ray meet
//! an occupied cell of this macrocell?" is eight ANDs with no walk through its cells.
//!
//! The macrocell is cut into its eight z-slices; within one, the ray's stretch spans an
//! x-range and a y-range of cells, and the rectangle they make holds every cell the ray
//! crosses there (a superset: the slice's corners beside the ray's path are included).
//! Ranges are widened by a rounding margin, so no cell that the walk would visit (with its
//! own arithmetic) is ever left out; an extra cell only costs a walk through the macrocell.

use glam::{IVec3, Vec3, Vec3A};

use super::cells::MACRO_SHIFT;
use crate::accel::Ray;

/// Cells along a macrocell's edge.
const SIDE: usize = 1 << MACRO_SHIFT;

/// A ray in the grid's cell units: at parameter `t` it is `origin + t·direction` cells from
/// the grid's lower corner.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellRay {
    origin: Vec3A,
    direction: Vec3A,
    /// `1 / direction` (±∞ on an axis the ray is parallel to).
    inverse: Vec3A,
    /// Margin, in cells, by which cell ranges are widened against rounding: the walk's
    /// cell-face distances and these positions differ by a few ulps of the distance in
    /// cells from the grid's corner.
    margin: f32,
}

impl CellRay {
    /// `ray` in the units of a grid whose lower corner is `corner` and whose cells measure
    /// `1 / inv_cell_size`; `t_end` is the largest parameter the walk reaches.
    #[inline(always)]
    pub fn new(ray: &Ray, corner: Vec3, inv_cell_size: Vec3, t_end: f32) -> CellRay {
        let origin = Vec3A::from((ray.origin - corner) * inv_cell_size);
        let direction = Vec3A::from(ray.direction * inv_cell_size);
        let reach = origin.abs().max_element() + direction.abs().max_element() * t_end.abs();
        CellRay {
            origin,
            direction,
            inverse: direction.recip(),
            margin: 1e-3 + 1e-5 * reach,
        }
    }

    /// The cells of the macrocell whose first cell is `base` that the ray touches for `t`
    /// in `[t_start, t_end]`, as occupancy words.
    #[inline(always)]
    pub fn macrocell_mask(&self, base: IVec3, t_start: f32, t_end: f32) -> [u64; SIDE] {
        let lo = base.as_vec3();
        let hi = lo + SIDE as f32;
        // The stretch within the macrocell's x and y slabs (z is cut slice by slice below).
        // A parallel axis gives ±∞ (no bound, or no stretch); NaN only when its origin lies
        // exactly on a grown slab's plane, a margin away from the cells, and then no stretch.
        let (mut t0, mut t1) = (t_start, t_end);
        for a in 0..2 {
            let ta = (lo[a] - self.margin - self.origin[a]) * self.inverse[a];
            let tb = (hi[a] + self.margin - self.origin[a]) * self.inverse[a];
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
        if !(t0 <= t1) {
            return [0; SIDE];
        }
        if self.direction.z == 0.0 {
            return self.parallel_mask(base, t0, t1);
        }
        // Slice by slice, lane by lane: written without branches over fixed arrays, so
        // that each line is one vector instruction.
        let o = self.origin - Vec3A::from(lo);
        let mut first = [[0u32; SIDE]; 2];
        let mut last = [[0u32; SIDE]; 2];
        let mut inside = [false; SIDE];
        for k in 0..SIDE {
            let ta = (k as f32 - self.margin - o.z) * self.inverse.z;
            let tb = ((k + 1) as f32 + self.margin - o.z) * self.inverse.z;
            let s0 = max(t0, min(ta, tb));
            let s1 = min(t1, max(ta, tb));
            inside[k] = s0 <= s1;
            for a in 0..2 {
                let p0 = o[a] + s0 * self.direction[a];
                let p1 = o[a] + s1 * self.direction[a];
                first[a][k] = local_cell(min(p0, p1) - self.margin);
                last[a][k] = local_cell(max(p0, p1) + self.margin);
            }
        }
        let mut words = [0u64; SIDE];
        for k in 0..SIDE {
            let word = slice_word(first[0][k], last[0][k], first[1][k], last[1][k]);
            words[k] = if inside[k] { word } else { 0 };
        }
        words
    }

    /// [`CellRay::macrocell_mask`] for a ray parallel to the slices, clipped to
    /// `[t0, t1]`: the one or two slices it lies in.
    fn parallel_mask(&self, base: IVec3, t0: f32, t1: f32) -> [u64; SIDE] {
        let o = self.origin - Vec3A::from(base.as_vec3());
        let mut words = [0u64; SIDE];
        let columns = [o.x + t0 * self.direction.x, o.x + t1 * self.direction.x];
        let rows = [o.y + t0 * self.direction.y, o.y + t1 * self.direction.y];
        let word = slice_word(
            local_cell(min(columns[0], columns[1]) - self.margin),
            local_cell(max(columns[0], columns[1]) + self.margin),
            local_cell(min(rows[0], rows[1]) - self.margin),
            local_cell(max(rows[0], rows[1]) + self.margin),
        );
        let first = local_cell(o.z - self.margin);
        let last = local_cell(o.z + self.margin);
        for word_z in &mut words[first as usize..=last as usize] {
            *word_z = word;
        }
        words
    }

    /// Where the ray enters and leaves cell `c`, grown by the margin on every side: `None`
    /// when it misses the grown cell or meets it only outside `[t_start, t_end]`.
    #[inline(always)]
    pub fn cell_span(&self, c: IVec3, t_start: f32, t_end: f32) -> Option<(f32, f32)> {
        let (near, far) = self.cell_interval(c, t_start, t_end);
        (near <= far).then_some((near, far))
    }

    /// [`CellRay::cell_span`]'s entries for eight cells of the macrocell starting at `base`, given
    /// by their coordinates within it lane by lane: each entry, or ∞ for a cell missed.
    #[inline(always)]
    pub fn cell_entries(
        &self,
        base: IVec3,
        cells: [&[f32]; 3],
        t_start: f32,
        t_end: f32,
        entries: &mut [f32],
    ) {
        let o = self.origin - Vec3A::from(base.as_vec3());
        let mut near = [t_start; 8];
        let mut far = [t_end; 8];
        for a in 0..3 {
            let (o, inverse, cells) = (o[a], self.inverse[a], &cells[a][..8]);
            for l in 0..8 {
                let ta = (cells[l] - self.margin - o) * inverse;
                let tb = (cells[l] + 1.0 + self.margin - o) * inverse;
                near[l] = max(near[l], min(ta, tb));
                far[l] = min(far[l], max(ta, tb));
            }
        }
        for l in 0..8 {
            entries[l] = if near[l] <= far[l] {
                near[l]
            } else {
                f32::INFINITY
            };
        }
    }

    #[inline(always)]
    fn cell_interval(&self, c: IVec3, t_start: f32, t_end: f32) -> (f32, f32) {
        let lo = Vec3A::from(c.as_vec3()) - self.margin;
        let hi = lo + (1.0 + 2.0 * self.margin);
        let ta = (lo - self.origin) * self.inverse;
        let tb = (hi - self.origin) * self.inverse;
        let near = max(ta.min(tb).max_element(), t_start);
        let far = min(ta.max(tb).min_element(), t_end);
        (near, far)
    }
}

/// The cell (0 to 7) of a macrocell that holds local coordinate `p`, clamped into the
/// macrocell (NaN gives 0).
#[inline(always)]
fn local_cell(p: f32) -> u32 {
    let c = max(p.floor(), 0.0);
    let c = min(c, (SIDE - 1) as f32);
    // SAFETY: `c` is a whole number in [0, 7] (NaN became 0 above).
    unsafe { c.to_int_unchecked::<u32>() }
}

/// A slice's occupancy word for columns `x0..=x1` of rows `y0..=y1`.
#[inline(always)]
fn slice_word(x0: u32, x1: u32, y0: u32, y1: u32) -> u64 {
    let mut columns = u64::from((0xffu32 >> (7 - (x1 - x0))) << x0);
    // The same columns in each row (byte) of the slice.
    columns |= columns << 8;
    columns |= columns << 16;
    columns |= columns << 32;
    let rows = (u64::MAX >> (8 * (7 - y1))) & (u64::MAX << (8 * y0));
    columns & rows
}

/// The smaller of two numbers, the second when either is NaN (one vector instruction,
/// unlike `f32::min`).
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The larger of two numbers, the second when either is NaN.
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

#[cfg(test)]
mod tests {
    use glam::UVec3;

    use super::*;
    use crate::accel::frame::GridFrame;
    use crate::render::sampling::Rng;
    use crate::scene::Aabb;

    /// Every cell the walk visits is in its macrocell's mask, for rays from outside and
    /// inside, oblique, axis-parallel, and through cell corners and faces.
    #[test]
    fn the_mask_holds_every_cell_the_walk_visits() {
        let mut rng = Rng::new(11, 3);
        let mut uniform = |lo: f32, hi: f32| lo + (hi - lo) * rng.uniform();
        let mut visited = 0usize;
        let mut extra = 0usize;
        for round in 0..3000 {
            let min = Vec3::new(uniform(-5.0, 5.0), uniform(-5.0, 5.0), uniform(-5.0, 5.0));
            let resolution = UVec3::new(
                uniform(1.0, 40.0) as u32,
                uniform(1.0, 40.0) as u32,
                uniform(1.0, 40.0) as u32,
            );
            let cell = Vec3::new(uniform(0.1, 2.0), uniform(0.1, 2.0), uniform(0.1, 2.0));
            let bounds = Aabb {
                min,
                max: min + resolution.as_vec3() * cell,
            };
            let frame = GridFrame::new(bounds, resolution);
            let inside = bounds.min
                + (bounds.max - bounds.min)
                    * Vec3::new(uniform(0.0, 1.0), uniform(0.0, 1.0), uniform(0.0, 1.0));
            let mut direction =
                Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
            let mut origin = match round % 3 {
                0 => inside,
                _ => inside - direction * uniform(1.0, 200.0),
            };
            // Some rays parallel to one or two axes, some starting on cell faces.
            match round % 7 {
                0 => direction.z = 0.0,
                1 => direction.x = 0.0,
                2 => {
                    direction.y = 0.0;
                    direction.z = 0.0;
                }
                3 => {
                    origin = bounds.min + (origin - bounds.min).round() * cell;
                    direction.z = 0.0;
                }
                4 => origin = bounds.min + ((origin - bounds.min) / cell).round() * cell,
                _ => {}
            }
            if direction == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(origin, direction);
            let Some(mut walk) = frame.start_walk(&ray) else {
                continue;
            };
            let cell_ray = CellRay::new(&ray, bounds.min, frame.inv_cell_size, walk.t_end);
            loop {
                let c = walk.cell;
                let base = (c >> MACRO_SHIFT) << MACRO_SHIFT;
                let mask = cell_ray.macrocell_mask(base, ray.t_min, walk.t_end);
                assert!(
                    cell_ray.cell_span(c, ray.t_min, walk.t_end).is_some(),
                    "round {round}: cell {c} is walked but the ray misses it"
                );
                let l = c - base;
                let bit = mask[l.z as usize] >> (l.x + 8 * l.y) & 1;
                assert_eq!(
                    bit, 1,
                    "round {round}: cell {c} is walked but not in the mask"
                );
                visited += 1;
                extra += mask.iter().map(|w| w.count_ones() as usize).sum::<usize>();
                if !walk.advance().1 {
                    break;
                }
            }
        }
        assert!(visited > 20_000, "{visited} cells walked");
        // The mask is a superset, but not all of the macrocell (a line crosses at most 22).
        let mean = extra as f64 / visited as f64;
        assert!(mean < 40.0, "{mean} cells per mask");
    }
}
