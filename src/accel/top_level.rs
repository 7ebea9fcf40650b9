//! A uniform grid over instances' world bounds: the top level above the per-mesh grids.
//!
//! The same frame and walk as the triangle grids ([`super::frame`]), with instance indices in
//! the cells their bounds touch (counting sort: count → prefix sum → place, as Lagae & Dutré
//! 2008 build their grids). A ray visits only the instances near it, front to back, and
//! stops once its nearest hit lies within the cell being visited, so its cost depends on
//! what it passes, not on how many instances the scene holds.

use glam::UVec3;

use super::Ray;
use super::grid::frame::{GridFrame, padded, resolution};
use crate::geometry::Aabb;

/// Cells per instance aimed for (λ of Cleary & Wyvill 1988). Instances are larger than
/// triangles relative to their spacing, so fewer cells per item than the triangle grids.
const DENSITY: f32 = 4.0;

/// Most cell references per instance on average (plus a fixed allowance): instances whose
/// bounds span the scene (a ground plane, a sky dome) touch every cell, and many of them must
/// not make the structure quadratic. The resolution is lowered until the references fit.
const REFERENCES_PER_INSTANCE: u64 = 16;
const REFERENCE_ALLOWANCE: u64 = 1 << 16;

/// Instance indices by cell.
pub(super) struct InstanceGrid {
    frame: GridFrame,
    /// Cell `c`'s instances are `ids[offsets[c]..offsets[c + 1]]`, in increasing order.
    offsets: Vec<u32>,
    ids: Vec<u32>,
}

impl InstanceGrid {
    /// A grid over the instances with these world bounds; empty and non-finite boxes are
    /// left out (nothing can be hit there). `None` when no box is left.
    pub fn build(bounds: &[Aabb]) -> Option<InstanceGrid> {
        let live: Vec<u32> = (0..bounds.len() as u32)
            .filter(|&i| {
                let b = &bounds[i as usize];
                !b.is_empty() && b.min.is_finite() && b.max.is_finite()
            })
            .collect();
        let all = live
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(bounds[i as usize]));
        if all.is_empty() {
            return None;
        }
        let all = padded(all);
        let budget = REFERENCES_PER_INSTANCE * live.len() as u64 + REFERENCE_ALLOWANCE;
        let mut r = resolution(all.extent(), live.len(), DENSITY);
        let frame = loop {
            let frame = GridFrame::new(all, r);
            let references: u64 = live
                .iter()
                .map(|&i| {
                    let (lo, hi) = frame.cells_of_box(&bounds[i as usize]);
                    let span = (hi - lo + UVec3::ONE).as_u64vec3();
                    span.x * span.y * span.z
                })
                .sum();
            if references <= budget || r == UVec3::ONE {
                break frame;
            }
            r = (r.as_vec3() * 0.8).floor().max(glam::Vec3::ONE).as_uvec3();
        };
        let mut counts = vec![0u32; frame.cell_count() + 1];
        let for_each_cell = |i: u32, f: &mut dyn FnMut(usize)| {
            let (lo, hi) = frame.cells_of_box(&bounds[i as usize]);
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        f(frame.cell_index(UVec3::new(x, y, z)));
                    }
                }
            }
        };
        for &i in &live {
            for_each_cell(i, &mut |c| counts[c + 1] += 1);
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let offsets = counts.clone();
        let mut ids = vec![0u32; *counts.last().unwrap() as usize];
        for &i in &live {
            for_each_cell(i, &mut |c| {
                ids[counts[c] as usize] = i;
                counts[c] += 1;
            });
        }
        Some(InstanceGrid {
            frame,
            offsets,
            ids,
        })
    }

    /// Calls `visit` with the instances of each non-empty cell along the ray, front to back,
    /// and the largest ray parameter that belongs to the cell, until it returns true.
    pub fn walk(&self, ray: &Ray, mut visit: impl FnMut(&[u32], f32) -> bool) {
        let Some(mut walk) = self.frame.start_walk::<false>(ray) else {
            return;
        };
        loop {
            let c = self.frame.cell_index(walk.cell().as_uvec3());
            let ids = &self.ids[self.offsets[c] as usize..self.offsets[c + 1] as usize];
            let (limit, more) = walk.advance();
            if !ids.is_empty() && visit(ids, limit) {
                return;
            }
            if !more {
                return;
            }
        }
    }

    /// Cells per axis.
    pub fn resolution(&self) -> UVec3 {
        self.frame.resolution
    }
}

/// The last few instances a ray has tested. An instance spans several cells; once tested,
/// its nearest hit (or its blocking) is already known, so testing it again is wasted work.
/// A ray-local ring rather than a per-instance stamp, so it is free of shared state.
pub(super) struct Mailbox {
    recent: [u32; 8],
    next: usize,
}

impl Mailbox {
    pub fn new() -> Mailbox {
        Mailbox {
            recent: [u32::MAX; 8],
            next: 0,
        }
    }

    /// True the first time `id` is offered (since it last fell out of the ring).
    #[inline]
    pub fn first_visit(&mut self, id: u32) -> bool {
        if self.recent.contains(&id) {
            return false;
        }
        self.recent[self.next] = id;
        self.next = (self.next + 1) % self.recent.len();
        true
    }
}
