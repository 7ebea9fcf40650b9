//! Coherent rays traced together: a packet of up to 64 rays of one octant (a tile of
//! camera rays) first crosses the empty space before the surface as one frustum, slab of
//! macrocells by slab of macrocells along its major axis (after the slab-by-slab frustum
//! walk of Wald, Ize, Kensler, Knoll & Parker 2006, "Ray tracing animated scenes using
//! coherent grid traversal", §3): each slab's rectangle of macrocells that could hold any
//! of its rays is read once, and the packet stops at the first slab where one of them is
//! occupied. A packet that finds none misses the mesh with every ray; otherwise each ray
//! walks on alone ([`Grid::intersect`]) from the plane where that slab begins.
//!
//! The grid's cells are about as wide as a camera pixel's footprint at the dragon's
//! resolutions, so sharing the walk cell by cell gains nothing: a packet that walked its
//! rectangle of cells slab by slab, testing each occupied cell against the rays whose own
//! rectangles held it, looked up 21 cells per ray on the full dragon's camera rays where a
//! ray alone steps through 2.8 (it leaps over empty space), and ran at 0.14–0.21× the
//! speed of single rays.
//!
//! Each ray's answer is bit for bit the one [`Grid::intersect`] gives it: no hit can lie
//! before the plane where its walk resumes, since every cell the ray crosses before it lies
//! in an empty macrocell (the frustum's rectangles hold the ray's path, grown by
//! [`margin`]), and the triangles of a cell are stored in every cell they touch; the walk
//! from there visits the same cells the whole walk visits from there on.

use glam::IVec3;

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
    /// or run nearly parallel to a cell face, walk alone from the start.
    pub fn intersect_packet(&self, rays: &[Ray], hits: &mut [Option<GridHit>]) {
        assert!(rays.len() <= PACKET_RAYS, "{} rays in a packet", rays.len());
        assert_eq!(rays.len(), hits.len(), "one hit per ray");
        dispatch(
            X86Level::Avx512,
            Packet {
                grid: self,
                rays,
                hits,
            },
        );
    }
}

/// A packet query, as a [`Kernel`] so that its lane loops are compiled for the widest
/// vector instructions the processor has.
struct Packet<'a> {
    grid: &'a Grid,
    rays: &'a [Ray],
    hits: &'a mut [Option<GridHit>],
}

impl Kernel for Packet<'_> {
    type Output = ();
    #[inline(always)]
    fn run<const FUSED: bool>(self) {
        let Packet { grid, rays, hits } = self;
        let single_cell = grid.frame.resolution == glam::UVec3::ONE;
        let lanes = if grid.blocks.is_empty() || single_cell {
            None
        } else {
            Lanes::gather(grid, rays)
        };
        let Some(lanes) = lanes else {
            for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
                *hit = grid.intersect(ray);
            }
            return;
        };
        let resume = first_occupied(grid, &lanes);
        for (r, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
            *hit = if lanes.packed & (1 << r) == 0 {
                grid.intersect(ray)
            } else if let Some(k) = resume {
                let t = lanes.crossing(r, lanes.signs[0] * k);
                (t < lanes.t_end[r])
                    .then(|| {
                        grid.intersect(&Ray {
                            t_min: ray.t_min.max(t),
                            ..*ray
                        })
                    })
                    .flatten()
            } else {
                None
            };
        }
    }
}

/// The lesser of `a` and `b` (`b` if either is NaN): unlike `f32::min`, one vector
/// instruction, so that lane loops run in vector lanes.
#[inline(always)]
fn lesser(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The greater of `a` and `b` (`b` if either is NaN), as [`lesser`].
#[inline(always)]
fn greater(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The least of `value(r)` over the lanes, in eight running minima so that the loop runs in
/// vector lanes (a single running minimum is a chain of dependent steps).
#[inline(always)]
fn least(value: impl Fn(usize) -> f32) -> f32 {
    let mut running = [f32::INFINITY; 8];
    for r in 0..PACKET_RAYS {
        running[r % 8] = lesser(running[r % 8], value(r));
    }
    running.into_iter().fold(f32::INFINITY, lesser)
}

/// The greatest of `value(r)` over the lanes, as [`least`].
#[inline(always)]
fn greatest(value: impl Fn(usize) -> f32) -> f32 {
    -least(|r| -value(r))
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
    /// Where the ray is within the grid's box (grown by the margin) and its own extent; an
    /// empty interval for an unpacked lane.
    t_start: [f32; PACKET_RAYS],
    t_end: [f32; PACKET_RAYS],
    margin: f32,
}

impl Lanes {
    /// The rays of `rays` that share the first suitable ray's octant, in cell coordinates;
    /// `None` when fewer than two rays can be packed. Lane by lane with no branch, so that
    /// it runs in vector lanes.
    #[inline(always)]
    fn gather(grid: &Grid, rays: &[Ray]) -> Option<Lanes> {
        let frame = &grid.frame;
        let (min, scale) = (frame.bounds.min, frame.inv_cell_size);
        let first = rays.iter().find_map(|ray| {
            let d = ray.direction * scale;
            let steep = d.abs().min_element() > SLANT_FRACTION * d.abs().max_element();
            (d.is_finite() && ray.origin.is_finite() && steep).then_some(d)
        })?;
        let major = first.abs().max_position();
        let axes = [major, (major + 1) % 3, (major + 2) % 3];
        let signs = axes.map(|a| first.signum()[a]);
        // The rays' origins and directions in cell coordinates, axis by axis in the order
        // k, u, v (lanes past the rays' count are zero, and left out below).
        let mut origin = [[0.0; PACKET_RAYS]; 3];
        let mut direction = [[0.0; PACKET_RAYS]; 3];
        for (i, &a) in axes.iter().enumerate() {
            for (r, ray) in rays.iter().enumerate() {
                origin[i][r] = (ray.origin[a] - min[a]) * scale[a];
                direction[i][r] = ray.direction[a] * scale[a];
            }
        }
        let largest = greater(
            frame.resolution.max_element() as f32,
            greatest(|r| {
                greater(
                    greater(origin[0][r].abs(), origin[1][r].abs()),
                    origin[2][r].abs(),
                )
            }),
        );
        let margin = margin(largest);
        let size = axes.map(|a| frame.resolution[a] as f32);
        let mut lanes = Lanes {
            packed: 0,
            axes,
            signs,
            origin,
            direction,
            inv_k: [0.0; PACKET_RAYS],
            t_start: [f32::INFINITY; PACKET_RAYS],
            t_end: [f32::NEG_INFINITY; PACKET_RAYS],
            margin,
        };
        for (r, ray) in rays.iter().enumerate() {
            let (mut start, mut end) = (ray.t_min, ray.t_max);
            let mut packed = largest.is_finite();
            let mut widest = 0.0f32;
            for i in 0..3 {
                widest = greater(widest, lanes.direction[i][r].abs());
            }
            for i in 0..3 {
                let (o, d) = (lanes.origin[i][r], lanes.direction[i][r]);
                let inv = 1.0 / d;
                packed &= (d * signs[i] > SLANT_FRACTION * widest) & inv.is_finite();
                let t0 = (-margin - o) * inv;
                let t1 = (size[i] + margin - o) * inv;
                start = greater(start, lesser(t0, t1));
                end = lesser(end, greater(t0, t1));
            }
            lanes.inv_k[r] = 1.0 / lanes.direction[0][r];
            lanes.t_start[r] = if packed { start } else { f32::INFINITY };
            lanes.t_end[r] = if packed { end } else { f32::NEG_INFINITY };
            lanes.packed |= u64::from(packed) << r;
        }
        (lanes.packed.count_ones() >= 2).then_some(lanes)
    }

    /// Where along k the first lane enters and the farthest one ends, as k and as the
    /// signed k (k times the walk's direction along it) the walk must reach; `None` when no
    /// lane meets the grid.
    fn extent(&self) -> Option<(f32, f32)> {
        let sign = self.signs[0];
        let first = least(|r| {
            let k = self.origin[0][r] + self.t_start[r] * self.direction[0][r];
            let live = self.t_start[r] <= self.t_end[r];
            if live { sign * k } else { f32::INFINITY }
        });
        (first < f32::INFINITY).then(|| (sign * first, self.reach()))
    }

    /// The farthest signed k (k times the walk's direction along it) a lane reaches before
    /// its extent ends, grown by the margin.
    #[inline(always)]
    fn reach(&self) -> f32 {
        let sign = self.signs[0];
        let reach = greatest(|r| {
            let k = self.origin[0][r] + self.t_end[r] * self.direction[0][r];
            let live = self.t_start[r] <= self.t_end[r];
            if live { sign * k } else { f32::NEG_INFINITY }
        });
        reach + self.margin
    }

    /// The parameter where lane `r` crosses the plane k = `k` (in cells).
    #[inline(always)]
    fn crossing(&self, r: usize, k: f32) -> f32 {
        (k - self.origin[0][r]) * self.inv_k[r]
    }
}

/// The packet's approach: the signed k (k times the walk's direction along it) of the plane
/// where the first slab of macrocells begins that holds an occupied macrocell in the
/// packet's rectangle, less the margin; `None` when no slab does.
#[inline(always)]
fn first_occupied(grid: &Grid, lanes: &Lanes) -> Option<f32> {
    let resolution = grid.frame.resolution;
    let axes = lanes.axes;
    let macro_slabs = (resolution[axes[0]] as i32 + (1 << MACRO_SHIFT) - 1) >> MACRO_SHIFT;
    let size = [resolution[axes[1]] as i32, resolution[axes[2]] as i32];
    let sign = lanes.signs[0];
    let (first, reach) = lanes.extent()?;
    let frustum = Frustum::of(lanes, first.floor());
    let side = (1 << MACRO_SHIFT) as f32;
    // Slab of macrocells m lies between the planes k = 8m and k = 8(m + 1) (the last one
    // may stick out of the grid: it holds no occupied cell there); `entry(m)` is the one
    // the packet crosses first.
    let entry = |m: i32| side * if sign > 0.0 { m as f32 } else { (m + 1) as f32 };
    let mut m = (first.floor() as i32 >> MACRO_SHIFT).clamp(0, macro_slabs - 1);
    while (0..macro_slabs).contains(&m) && sign * entry(m) <= reach {
        let next = m + sign as i32;
        if let Some((lo, hi)) = frustum.rectangle(entry(m), entry(next), size)
            && any_occupied(grid, axes, m, lo, hi)
        {
            return Some(sign * entry(m) - lanes.margin);
        }
        m = next;
    }
    None
}

/// True when a macrocell of slab `m` (along `axes[0]`) within the cells `lo` to `hi` (along
/// the other two) is occupied.
#[inline(always)]
fn any_occupied(grid: &Grid, axes: [usize; 3], m: i32, lo: [i32; 2], hi: [i32; 2]) -> bool {
    for v in (lo[1] >> MACRO_SHIFT)..=(hi[1] >> MACRO_SHIFT) {
        for u in (lo[0] >> MACRO_SHIFT)..=(hi[0] >> MACRO_SHIFT) {
            let mut c = [0; 3];
            (c[axes[0]], c[axes[1]], c[axes[2]]) = (m, u, v);
            if grid.cells.macrocell_occupied(IVec3::from(c) << MACRO_SHIFT) {
                return true;
            }
        }
    }
    false
}

/// Bounds of the whole packet's positions along u and v as functions of k, found once:
/// each lane's position on the plane k = `k_ref` and its slope (du/dk, dv/dk), each taken
/// between its least and greatest over the lanes. The rectangle they give over a slab
/// holds every lane's, more loosely where the lanes' origins differ, at no cost per lane;
/// the lanes' own rectangles are worked out only in slabs where the packet's holds an
/// occupied cell.
struct Frustum {
    k_ref: f32,
    at_lo: [f32; 2],
    at_hi: [f32; 2],
    slope_lo: [f32; 2],
    slope_hi: [f32; 2],
    margin: f32,
}

impl Frustum {
    fn of(lanes: &Lanes, k_ref: f32) -> Frustum {
        let mut f = Frustum {
            k_ref,
            at_lo: [f32::INFINITY; 2],
            at_hi: [f32::NEG_INFINITY; 2],
            slope_lo: [f32::INFINITY; 2],
            slope_hi: [f32::NEG_INFINITY; 2],
            margin: 0.0,
        };
        let live = |r: usize| lanes.t_start[r] <= lanes.t_end[r];
        let mut spread = 0.0f32;
        for i in 0..2 {
            let slope = |r: usize| lanes.direction[i + 1][r] * lanes.inv_k[r];
            let at = |r: usize| lanes.origin[i + 1][r] + (k_ref - lanes.origin[0][r]) * slope(r);
            let or = |r: usize, value: f32, none: f32| if live(r) { value } else { none };
            f.at_lo[i] = least(|r| or(r, at(r), f32::INFINITY));
            f.at_hi[i] = greatest(|r| or(r, at(r), f32::NEG_INFINITY));
            f.slope_lo[i] = least(|r| or(r, slope(r), f32::INFINITY));
            f.slope_hi[i] = greatest(|r| or(r, slope(r), f32::NEG_INFINITY));
            spread = greater(spread, greater(f.at_hi[i].abs(), f.at_lo[i].abs()));
        }
        // The lanes' rectangles are grown by their margin; these bounds carry the rounding
        // of another way of working out the same positions besides.
        f.margin = 2.0 * lanes.margin + 1e-5 * spread;
        f
    }

    /// The cells (first and last along u and v) the packet's rectangle over the slab
    /// between the planes k = `a` and k = `b` holds, within a grid of `size`; `None` when
    /// it lies outside the grid.
    #[inline(always)]
    fn rectangle(&self, a: f32, b: f32, size: [i32; 2]) -> Option<([i32; 2], [i32; 2])> {
        let mut lo = [0; 2];
        let mut hi = [0; 2];
        for i in 0..2 {
            let bound = |k: f32, at: f32, slope_lo: f32, slope_hi: f32, low: bool| {
                let dk = k - self.k_ref;
                let (p, q) = (at + dk * slope_lo, at + dk * slope_hi);
                if low { p.min(q) } else { p.max(q) }
            };
            let (sl, sh) = (self.slope_lo[i], self.slope_hi[i]);
            let low =
                bound(a, self.at_lo[i], sl, sh, true).min(bound(b, self.at_lo[i], sl, sh, true));
            let high =
                bound(a, self.at_hi[i], sl, sh, false).max(bound(b, self.at_hi[i], sl, sh, false));
            lo[i] = (low - self.margin).floor().max(0.0) as i32;
            hi[i] = (high + self.margin).floor().min((size[i] - 1) as f32) as i32;
            if lo[i] > hi[i] {
                return None;
            }
        }
        Some((lo, hi))
    }
}
