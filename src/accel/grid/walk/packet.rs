//! Coherent rays traced together: a packet of up to 64 rays of one octant walks the grid
//! slab by slab along its major axis (Wald, Ize, Kensler, Knoll & Parker 2006, "Ray tracing
//! animated scenes using coherent grid traversal", §3). In each slab of cells the packet
//! covers a rectangle of cells, the union of its rays' own rectangles there; each occupied
//! cell in it is looked up once, its blocks asked for once, and tested against each ray
//! whose own rectangle holds the cell. A slab of macrocells whose rectangle holds no
//! occupied macrocell is passed in one step.
//!
//! Each ray's answer is the one [`Grid::intersect`] gives it. A ray is tested against every
//! cell its walk visits (its rectangle in a slab holds the cells it crosses there, grown by
//! [`margin`]), with the same triangle test, and the cells of a slab are taken in the order
//! of the ray's direction on both other axes, so of the cells a ray crosses each comes
//! after those it crosses before. A ray stops once its nearest hit lies at or before the
//! plane where it leaves a slab, where its walk stops too: every triangle not yet tested
//! lies beyond that plane. The cells a rectangle adds beside a ray's own path hold only
//! triangles the ray would meet in a cell of its path, so only a tie between two triangles
//! hit at exactly the same parameter could be settled otherwise, as a cell's boxes may
//! settle it ([`crate::accel::grid::storage::cell_box`]).

use glam::{IVec3, Vec3};

use super::prefetch::prefetch;
use crate::accel::Ray;
use crate::accel::grid::storage::macrocell::MACRO_SHIFT;
use crate::accel::grid::{Grid, GridHit};
use crate::accel::isa::{Kernel, X86Level, dispatch};

/// Most rays in one packet: an 8 × 8 tile of pixels.
pub const PACKET_RAYS: usize = 64;

/// A ray whose direction along some axis is below this fraction of its largest component
/// is traced alone: across a slab it would sweep a rectangle of many cells.
const SLANT_FRACTION: f32 = 1e-3;

impl Grid {
    /// The closest hit along each of `rays` (at most [`PACKET_RAYS`]) into `hits`: for each
    /// ray what [`Grid::intersect`] answers. Rays that do not share the first one's octant,
    /// or run nearly parallel to a cell face, are traced alone.
    pub fn intersect_packet(&self, rays: &[Ray], hits: &mut [Option<GridHit>]) {
        assert!(rays.len() <= PACKET_RAYS, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), hits.len(), "one hit per ray");
        let single_cell = self.frame.resolution == glam::UVec3::ONE;
        let lanes = if self.blocks.is_empty() || single_cell {
            None
        } else {
            Lanes::gather(self, rays)
        };
        let Some(mut lanes) = lanes else {
            for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
                *hit = self.intersect(ray);
            }
            return;
        };
        for (r, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
            if lanes.packed & (1 << r) == 0 {
                *hit = self.intersect(ray);
            }
        }
        dispatch(
            X86Level::Avx512,
            PacketWalk {
                grid: self,
                rays,
                lanes: &mut lanes,
            },
        );
        for (r, hit) in hits.iter_mut().enumerate() {
            if lanes.packed & (1 << r) != 0 {
                *hit = lanes.nearest[r];
            }
        }
    }
}

/// How far, in cells, each ray's rectangle and slab are grown: well beyond the rounding of
/// the positions the packet computes (a few ulps of the largest cell coordinate it meets,
/// an origin far outside the grid included), so no cell a ray's walk visits is left out.
fn margin(largest_coordinate: f32) -> f32 {
    1e-3 + 1e-5 * largest_coordinate
}

/// The packet's rays lane by lane, in the grid's cell coordinates with the axes permuted so
/// that `k` is the major axis the packet walks along and `u`, `v` the other two.
struct Lanes {
    /// Lanes traced in the packet (the others are traced alone).
    packed: u64,
    /// Axis numbers of k, u and v.
    axes: [usize; 3],
    /// Direction signs along k, u and v (+1 or −1), the same for every packed ray.
    signs: [f32; 3],
    origin: [[f32; PACKET_RAYS]; 3],
    direction: [[f32; PACKET_RAYS]; 3],
    /// 1 / direction along k.
    inv_k: [f32; PACKET_RAYS],
    /// Where the ray is within the grid's box (grown by the margin) and its own extent;
    /// `t_end` shrinks to the nearest hit. An empty interval for an unpacked lane.
    t_start: [f32; PACKET_RAYS],
    t_end: [f32; PACKET_RAYS],
    /// The nearest hit found so far, and the bound a further hit must beat.
    nearest: [Option<GridHit>; PACKET_RAYS],
    t_nearest: [f32; PACKET_RAYS],
    margin: f32,
}

impl Lanes {
    /// The rays of `rays` that share the first suitable ray's octant, in cell coordinates;
    /// `None` when fewer than two rays can be packed.
    fn gather(grid: &Grid, rays: &[Ray]) -> Option<Lanes> {
        let frame = &grid.frame;
        let to_cells = |p: Vec3| (p - frame.bounds.min) * frame.inv_cell_size;
        let suitable = |ray: &Ray| {
            let d = ray.direction * frame.inv_cell_size;
            let o = to_cells(ray.origin);
            let steep = d.abs().min_element() > SLANT_FRACTION * d.abs().max_element();
            (d.is_finite() && o.is_finite() && steep).then_some((o, d))
        };
        let (_, first) = rays.iter().find_map(suitable)?;
        let major = first.abs().max_position();
        let axes = [major, (major + 1) % 3, (major + 2) % 3];
        let octant = first.signum();
        let mut lanes = Lanes {
            packed: 0,
            axes,
            signs: axes.map(|a| octant[a]),
            origin: [[0.0; PACKET_RAYS]; 3],
            direction: [[0.0; PACKET_RAYS]; 3],
            inv_k: [0.0; PACKET_RAYS],
            t_start: [f32::INFINITY; PACKET_RAYS],
            t_end: [f32::NEG_INFINITY; PACKET_RAYS],
            nearest: [None; PACKET_RAYS],
            t_nearest: [f32::NEG_INFINITY; PACKET_RAYS],
            margin: 0.0,
        };
        let mut largest = frame.resolution.max_element() as f32;
        for (r, ray) in rays.iter().enumerate() {
            let Some((o, d)) = suitable(ray).filter(|(_, d)| d.signum() == octant) else {
                continue;
            };
            lanes.packed |= 1 << r;
            for (i, &a) in axes.iter().enumerate() {
                lanes.origin[i][r] = o[a];
                lanes.direction[i][r] = d[a];
            }
            lanes.inv_k[r] = 1.0 / d[major];
            lanes.t_nearest[r] = ray.t_max;
            largest = largest.max(o.abs().max_element());
        }
        if lanes.packed.count_ones() < 2 {
            return None;
        }
        lanes.margin = margin(largest);
        let size = frame.resolution.as_vec3();
        for (r, ray) in rays.iter().enumerate() {
            if lanes.packed & (1 << r) != 0 {
                let (start, end) = lanes.clip(r, size, ray);
                lanes.t_start[r] = start;
                lanes.t_end[r] = end;
            }
        }
        Some(lanes)
    }

    /// Where lane `r` (of `ray`) enters and leaves the grid's box of `size` cells, grown by
    /// the margin, within the ray's own extent.
    fn clip(&self, r: usize, size: Vec3, ray: &Ray) -> (f32, f32) {
        let (mut start, mut end) = (ray.t_min, ray.t_max);
        for i in 0..3 {
            let (o, d) = (self.origin[i][r], self.direction[i][r]);
            let n = size[self.axes[i]];
            let t0 = (-self.margin - o) / d;
            let t1 = (n + self.margin - o) / d;
            start = start.max(t0.min(t1));
            end = end.min(t0.max(t1));
        }
        (start, end)
    }

    /// Parameters where lane `r` crosses the planes k = `near` and k = `far` (in cells).
    #[inline(always)]
    fn crossing(&self, r: usize, near: f32, far: f32) -> (f32, f32) {
        let (o, inv) = (self.origin[0][r], self.inv_k[r]);
        ((near - o) * inv, (far - o) * inv)
    }
}

/// Each lane's cell rectangle in one slab: first and last cell along u and v (empty when
/// the first exceeds the last).
struct Rectangles {
    lo: [[i32; PACKET_RAYS]; 2],
    hi: [[i32; PACKET_RAYS]; 2],
}

impl Rectangles {
    /// The rectangles of every lane over the slab between the planes k = `from` and
    /// k = `to` (in the walk's order), grown by the margin, for a grid of `size` cells
    /// along u and v.
    #[inline(always)]
    fn over(lanes: &Lanes, from: f32, to: f32, size: [i32; 2]) -> Rectangles {
        let m = lanes.margin;
        let sign = lanes.signs[0];
        let (near, far) = (from - sign * m, to + sign * m);
        let mut rect = Rectangles {
            lo: [[0; PACKET_RAYS]; 2],
            hi: [[-1; PACKET_RAYS]; 2],
        };
        for r in 0..PACKET_RAYS {
            let (t_near, t_far) = lanes.crossing(r, near, far);
            let a = t_near.max(lanes.t_start[r]);
            let b = t_far.min(lanes.t_end[r]);
            let inside = a <= b;
            for i in 0..2 {
                let (o, d) = (lanes.origin[i + 1][r], lanes.direction[i + 1][r]);
                let (pa, pb) = (o + a * d, o + b * d);
                let lo = (pa.min(pb) - m).floor().max(0.0) as i32;
                let hi = (pa.max(pb) + m).floor().min((size[i] - 1) as f32) as i32;
                rect.lo[i][r] = if inside { lo } else { 0 };
                rect.hi[i][r] = if inside { hi } else { -1 };
            }
        }
        rect
    }

    /// The rectangle holding every lane's: first and last cell along u and v; `None` when
    /// no lane's is in the slab.
    #[inline(always)]
    fn union(&self) -> Option<([i32; 2], [i32; 2])> {
        let mut lo = [i32::MAX; 2];
        let mut hi = [i32::MIN; 2];
        for r in 0..PACKET_RAYS {
            let live = (self.lo[0][r] <= self.hi[0][r]) & (self.lo[1][r] <= self.hi[1][r]);
            for i in 0..2 {
                lo[i] = lo[i].min(if live { self.lo[i][r] } else { i32::MAX });
                hi[i] = hi[i].max(if live { self.hi[i][r] } else { i32::MIN });
            }
        }
        (lo[0] <= hi[0]).then_some((lo, hi))
    }

    /// The lanes whose rectangle holds cell (`u`, `v`).
    #[inline(always)]
    fn holding(&self, u: i32, v: i32) -> u64 {
        let mut mask = 0u64;
        for r in 0..PACKET_RAYS {
            let inside = (self.lo[0][r] <= u)
                & (u <= self.hi[0][r])
                & (self.lo[1][r] <= v)
                & (v <= self.hi[1][r]);
            mask |= u64::from(inside) << r;
        }
        mask
    }
}

/// The cells from `lo` to `hi` in the order of `sign` (first to last for +1).
fn ordered(lo: i32, hi: i32, sign: f32) -> impl Iterator<Item = i32> {
    let forward = sign > 0.0;
    (0..(hi - lo + 1).max(0)).map(move |i| if forward { lo + i } else { hi - i })
}

/// The packet's walk, as a [`Kernel`] so that its lane loops are compiled for the widest
/// vector instructions the processor has.
struct PacketWalk<'a> {
    grid: &'a Grid,
    rays: &'a [Ray],
    lanes: &'a mut Lanes,
}

impl Kernel for PacketWalk<'_> {
    type Output = ();
    #[inline(always)]
    fn run<const FUSED: bool>(mut self) {
        self.walk();
    }
}

impl PacketWalk<'_> {
    /// The grid's cell coordinates of slab `s`'s cell (`u`, `v`).
    #[inline(always)]
    fn cell(&self, s: i32, u: i32, v: i32) -> IVec3 {
        let mut c = [0; 3];
        let axes = self.lanes.axes;
        (c[axes[0]], c[axes[1]], c[axes[2]]) = (s, u, v);
        IVec3::from(c)
    }

    /// The walk: slabs of macrocells along k, and within one that holds an occupied
    /// macrocell in the packet's rectangle, its slabs of cells.
    #[inline(always)]
    fn walk(&mut self) {
        let lanes = &*self.lanes;
        let resolution = self.grid.frame.resolution;
        let axes = lanes.axes;
        let slabs = resolution[axes[0]] as i32;
        let size = [resolution[axes[1]] as i32, resolution[axes[2]] as i32];
        let sign = lanes.signs[0];
        // The first slab any lane enters.
        let mut first = i32::MAX;
        let mut last = i32::MIN;
        for r in 0..PACKET_RAYS {
            if lanes.t_start[r] <= lanes.t_end[r] {
                let k = lanes.origin[0][r] + lanes.t_start[r] * lanes.direction[0][r];
                let s = (k.floor() as i32).clamp(0, slabs - 1);
                first = first.min(s);
                last = last.max(s);
            }
        }
        if first > last {
            return;
        }
        let side = 1 << MACRO_SHIFT;
        let mut s = if sign > 0.0 { first } else { last };
        while (0..slabs).contains(&s) {
            let m = s >> MACRO_SHIFT;
            let (m_lo, m_hi) = (m * side, (m * side + side).min(slabs));
            let (from, to, end) = if sign > 0.0 {
                (s as f32, m_hi as f32, m_hi)
            } else {
                ((s + 1) as f32, m_lo as f32, m_lo - 1)
            };
            if self.macro_slab_occupied(s, from, to, size) {
                while s != end {
                    let (near, far) = if sign > 0.0 {
                        (s as f32, (s + 1) as f32)
                    } else {
                        ((s + 1) as f32, s as f32)
                    };
                    self.slab(s, near, far, size);
                    if !self.any_beyond(far) {
                        return;
                    }
                    s += sign as i32;
                }
            } else if !self.any_beyond(to) {
                return;
            }
            s = end;
        }
    }

    /// True when the packet's rectangle between the planes `from` and `to` (slab `s`'s
    /// macrocell slab, from `s` on) holds an occupied macrocell.
    #[inline(always)]
    fn macro_slab_occupied(&self, s: i32, from: f32, to: f32, size: [i32; 2]) -> bool {
        let rect = Rectangles::over(self.lanes, from, to, size);
        let Some((lo, hi)) = rect.union() else {
            return false;
        };
        let cells = &self.grid.cells;
        for v in (lo[1] >> MACRO_SHIFT)..=(hi[1] >> MACRO_SHIFT) {
            for u in (lo[0] >> MACRO_SHIFT)..=(hi[0] >> MACRO_SHIFT) {
                let c = self.cell(s, u << MACRO_SHIFT, v << MACRO_SHIFT);
                if cells.macrocell_of(c, 0).is_ok() {
                    return true;
                }
            }
        }
        false
    }

    /// True when some lane may still find a nearer hit beyond the plane k = `far`; lanes
    /// whose nearest hit lies at or before it, or which end before it, are done.
    #[inline(always)]
    fn any_beyond(&mut self, far: f32) -> bool {
        let lanes = &mut *self.lanes;
        let mut any = false;
        for r in 0..PACKET_RAYS {
            let t_far = (far - lanes.origin[0][r]) * lanes.inv_k[r];
            let beyond = t_far < lanes.t_end[r];
            any |= beyond;
            lanes.t_end[r] = if beyond {
                lanes.t_end[r]
            } else {
                f32::NEG_INFINITY
            };
        }
        any
    }

    /// Tests slab `s` (between the planes k = `near` and k = `far`): each occupied cell of
    /// the packet's rectangle against the lanes whose rectangles hold it.
    #[inline(always)]
    fn slab(&mut self, s: i32, near: f32, far: f32, size: [i32; 2]) {
        let rect = Rectangles::over(self.lanes, near, far, size);
        let Some((lo, hi)) = rect.union() else {
            return;
        };
        let signs = self.lanes.signs;
        let mut found: [(i32, i32, usize, usize); PACKET_RAYS] = [(0, 0, 0, 0); PACKET_RAYS];
        let mut count = 0;
        let cells = &self.grid.cells;
        for v in ordered(lo[1], hi[1], signs[2]) {
            for u in ordered(lo[0], hi[0], signs[1]) {
                let c = self.cell(s, u, v);
                let Ok(record) = cells.macrocell_of(c, 0) else {
                    continue;
                };
                if let Some(blocks) = cells.blocks_in(record, c) {
                    for block in &self.grid.blocks[blocks.clone()] {
                        prefetch(block);
                    }
                    if count == PACKET_RAYS {
                        self.test_cells(&rect, &found[..count]);
                        count = 0;
                    }
                    found[count] = (u, v, blocks.start, blocks.end);
                    count += 1;
                }
            }
        }
        self.test_cells(&rect, &found[..count]);
    }

    /// Tests the blocks of each of `cells` (u, v and the range of its blocks) against the
    /// lanes whose rectangles hold the cell.
    #[inline(always)]
    fn test_cells(&mut self, rect: &Rectangles, cells: &[(i32, i32, usize, usize)]) {
        let lanes = &mut *self.lanes;
        for &(u, v, start, end) in cells {
            let mut mask = rect.holding(u, v);
            while mask != 0 {
                let r = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let ray = &self.rays[r];
                for block in &self.grid.blocks[start..end] {
                    if let Some(hit) = block.nearest(ray, lanes.t_nearest[r]) {
                        lanes.t_nearest[r] = hit.t;
                        lanes.nearest[r] = Some(hit.into());
                    }
                }
            }
        }
        for r in 0..PACKET_RAYS {
            lanes.t_end[r] = lanes.t_end[r].min(lanes.t_nearest[r]);
        }
    }
}
