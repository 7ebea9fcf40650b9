//! From a uniform grid of voxels to the cells of an irregular grid, after Pérard-Gayot,
//! Kalojanov & Slusallek (2017), "GPU ray tracing using irregular grids" (§3.2–3.3):
//!
//! - **Merging.** Neighbouring cells of equal extent become one box while that lowers the
//!   expected cost of a ray crossing them, the surface-area estimate
//!   `area × (1 + block_cost × blocks)` (MacDonald & Booth 1990). Empty space merges into
//!   large boxes; a triangle spread over several small cells is then stored once.
//!   Cells pair like buddies (a cell of size 2^k on an axis, at a multiple of 2^(k+1), with
//!   the cell just after it), axes in turn, level by level, so no two merges of one pass
//!   touch the same cell and every cell stays a box.
//! - **Expansion.** Each cell's box is then grown, one layer of voxels at a time, over
//!   neighbours whose triangles it holds too (every empty one included). The grown box is
//!   used only to find where a ray leaves the cell: every triangle met inside it is among
//!   the cell's own, so a hit before that exit is the nearest one, and the ray leaps there
//!   in one step.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::block::LANES;

/// Rounds of expansion: each grows every face by at most one layer of voxels.
const EXPANSION_ROUNDS: u32 = 16;

/// A merged cell: its voxels (inclusive corners), the box it answers for after expansion,
/// and its triangles (sorted mesh indices) in the build's pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct MergedCell {
    pub lo: [u16; 3],
    pub hi: [u16; 3],
    pub reach_lo: [u16; 3],
    pub reach_hi: [u16; 3],
    pub start: u32,
    pub len: u32,
}

/// The cells of an irregular grid, and which cell each voxel belongs to.
pub(super) struct Merged {
    /// Voxel (x fastest, then y, then z) → index into `cells`.
    pub map: Vec<u32>,
    pub cells: Vec<MergedCell>,
    /// The triangle lists the cells point into.
    pub pool: Vec<u32>,
}

impl Merged {
    /// The triangles of `cell`.
    pub fn triangles(&self, cell: &MergedCell) -> &[u32] {
        &self.pool[cell.start as usize..(cell.start + cell.len) as usize]
    }
}

/// Merges and expands the voxels of a grid of `resolution` voxels of `voxel_size`, voxel
/// `v` holding `pool[start[v]..start[v + 1]]` (sorted); `block_cost` is the cost of testing
/// one block of triangles relative to one step of the walk.
pub(super) fn merge_voxels(
    resolution: UVec3,
    voxel_size: Vec3,
    start: &[u32],
    pool: Vec<u32>,
    block_cost: f32,
) -> Merged {
    let r = resolution.to_array();
    let count = start.len() - 1;
    let index = |c: [u16; 3]| {
        c[0] as usize + r[0] as usize * (c[1] as usize + r[1] as usize * c[2] as usize)
    };
    let coords = |v: usize| {
        let x = v % r[0] as usize;
        let y = (v / r[0] as usize) % r[1] as usize;
        let z = v / (r[0] as usize * r[1] as usize);
        [x as u16, y as u16, z as u16]
    };
    let mut cells: Vec<MergedCell> = (0..count)
        .into_par_iter()
        .map(|v| {
            let c = coords(v);
            MergedCell {
                lo: c,
                hi: c,
                reach_lo: c,
                reach_hi: c,
                start: start[v],
                len: start[v + 1] - start[v],
            }
        })
        .collect();
    let mut map: Vec<u32> = (0..count as u32).collect();
    let mut alive: Vec<u32> = (0..count as u32).collect();
    let mut dead = vec![false; count];
    let mut pool = pool;
    let mut union = Vec::new();
    let cost = |lo: [u16; 3], hi: [u16; 3], len: usize| {
        let e = Vec3::new(
            (hi[0] - lo[0] + 1) as f32,
            (hi[1] - lo[1] + 1) as f32,
            (hi[2] - lo[2] + 1) as f32,
        ) * voxel_size;
        let area = e.x * e.y + e.y * e.z + e.z * e.x;
        area * (1.0 + block_cost * len.div_ceil(LANES) as f32)
    };
    let levels = 32 - (r.iter().max().copied().unwrap_or(1).max(1) - 1).leading_zeros();
    for level in 0..levels {
        let size = 1u16 << level;
        for axis in 0..3 {
            let mut merges = 0usize;
            for &c in &alive {
                let a = cells[c as usize];
                if a.hi[axis] - a.lo[axis] + 1 != size || a.lo[axis] % (2 * size) != 0 {
                    continue;
                }
                let next = a.hi[axis] as u32 + 1;
                if next >= r[axis] {
                    continue;
                }
                let mut probe = a.lo;
                probe[axis] = next as u16;
                let d = map[index(probe)];
                let b = cells[d as usize];
                let mut far = a.hi;
                far[axis] = b.hi[axis];
                if b.lo != probe || b.hi != far || b.hi[axis] - b.lo[axis] + 1 != size {
                    continue;
                }
                let la = &pool[a.start as usize..(a.start + a.len) as usize];
                let lb = &pool[b.start as usize..(b.start + b.len) as usize];
                union.clear();
                sorted_union(la, lb, &mut union);
                let before = cost(a.lo, a.hi, la.len()) + cost(b.lo, b.hi, lb.len());
                if cost(a.lo, b.hi, union.len()) > before {
                    continue;
                }
                let (start, len) = if union.len() == la.len() {
                    (a.start, a.len)
                } else if union.len() == lb.len() {
                    (b.start, b.len)
                } else {
                    let start = pool.len() as u32;
                    pool.extend_from_slice(&union);
                    (start, union.len() as u32)
                };
                cells[c as usize] = MergedCell {
                    hi: b.hi,
                    reach_hi: b.hi,
                    start,
                    len,
                    ..a
                };
                for z in b.lo[2]..=b.hi[2] {
                    for y in b.lo[1]..=b.hi[1] {
                        for x in b.lo[0]..=b.hi[0] {
                            map[index([x, y, z])] = c;
                        }
                    }
                }
                dead[d as usize] = true;
                merges += 1;
            }
            if merges > 0 {
                alive.retain(|&c| !dead[c as usize]);
            }
        }
    }
    // Expansion reads the merged partition only, so cells grow independently.
    let reaches: Vec<([u16; 3], [u16; 3])> = alive
        .par_iter()
        .map(|&c| expand(&cells[c as usize], &cells, &map, &pool, r))
        .collect();
    let mut number = vec![0u32; count];
    let mut out = Vec::with_capacity(alive.len());
    for (k, (&c, (reach_lo, reach_hi))) in alive.iter().zip(reaches).enumerate() {
        number[c as usize] = k as u32;
        out.push(MergedCell {
            reach_lo,
            reach_hi,
            ..cells[c as usize]
        });
    }
    map.par_iter_mut().for_each(|m| *m = number[*m as usize]);
    Merged {
        map,
        cells: out,
        pool,
    }
}

/// The box `cell` answers for: its own, grown face by face while every voxel of the next
/// layer belongs to a cell whose triangles are among its own.
fn expand(
    cell: &MergedCell,
    cells: &[MergedCell],
    map: &[u32],
    pool: &[u32],
    r: [u32; 3],
) -> ([u16; 3], [u16; 3]) {
    let own = &pool[cell.start as usize..(cell.start + cell.len) as usize];
    let index = |c: [u16; 3]| {
        c[0] as usize + r[0] as usize * (c[1] as usize + r[1] as usize * c[2] as usize)
    };
    // The last neighbour asked about and the answer (a layer mostly meets a few cells).
    let mut known: Option<(u32, bool)> = None;
    let mut covered = |id: u32| {
        if let Some((k, answer)) = known
            && k == id
        {
            return answer;
        }
        let n = &cells[id as usize];
        let theirs = &pool[n.start as usize..(n.start + n.len) as usize];
        let answer = is_sorted_subset(theirs, own);
        known = Some((id, answer));
        answer
    };
    let (mut lo, mut hi) = (cell.lo, cell.hi);
    for _ in 0..EXPANSION_ROUNDS {
        let mut grew = false;
        for axis in 0..3 {
            for upward in [false, true] {
                let layer = if upward {
                    if hi[axis] as u32 + 1 >= r[axis] {
                        continue;
                    }
                    hi[axis] + 1
                } else {
                    if lo[axis] == 0 {
                        continue;
                    }
                    lo[axis] - 1
                };
                let (mut a, mut b) = (lo, hi);
                a[axis] = layer;
                b[axis] = layer;
                let mut fits = true;
                'layer: for z in a[2]..=b[2] {
                    for y in a[1]..=b[1] {
                        for x in a[0]..=b[0] {
                            if !covered(map[index([x, y, z])]) {
                                fits = false;
                                break 'layer;
                            }
                        }
                    }
                }
                if fits {
                    if upward {
                        hi[axis] = layer;
                    } else {
                        lo[axis] = layer;
                    }
                    grew = true;
                }
            }
        }
        if !grew {
            break;
        }
    }
    (lo, hi)
}

/// Appends the sorted union of two sorted lists to `out`.
fn sorted_union(a: &[u32], b: &[u32], out: &mut Vec<u32>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

/// True when every element of sorted `small` is in sorted `large`.
fn is_sorted_subset(small: &[u32], large: &[u32]) -> bool {
    if small.len() > large.len() {
        return false;
    }
    let mut j = 0;
    for &x in small {
        while j < large.len() && large[j] < x {
            j += 1;
        }
        if j == large.len() || large[j] != x {
            return false;
        }
        j += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_and_subset_of_sorted_lists() {
        let mut out = Vec::new();
        sorted_union(&[1, 3, 5], &[2, 3, 9], &mut out);
        assert_eq!(out, [1, 2, 3, 5, 9]);
        assert!(is_sorted_subset(&[], &[1]));
        assert!(is_sorted_subset(&[3, 9], &[1, 2, 3, 5, 9]));
        assert!(!is_sorted_subset(&[4], &[1, 2, 3, 5, 9]));
        assert!(!is_sorted_subset(&[1, 2], &[2]));
    }

    /// A 4×4×4 grid, empty but for one triangle in voxel (1, 1, 1): the empty space merges
    /// into a few boxes, every voxel's cell holds it, and the occupied cell grows over its
    /// empty neighbours as far as the grid allows.
    #[test]
    fn empty_space_merges_and_cells_expand_over_empty_neighbours() {
        let r = UVec3::splat(4);
        let occupied = 1 + 4 + 16;
        let start: Vec<u32> = (0..=64u32).map(|v| u32::from(v > occupied)).collect();
        let merged = merge_voxels(r, Vec3::ONE, &start, vec![7], 1.0);
        assert!(merged.cells.len() < 16, "{} cells", merged.cells.len());
        for v in 0..64usize {
            let c = &merged.cells[merged.map[v] as usize];
            let p = [v % 4, (v / 4) % 4, v / 16].map(|x| x as u16);
            assert!((0..3).all(|a| c.lo[a] <= p[a] && p[a] <= c.hi[a]), "voxel {v}");
            assert_eq!(c.len, u32::from(v == occupied as usize), "voxel {v}");
        }
        let full = &merged.cells[merged.map[occupied as usize] as usize];
        assert_eq!(merged.triangles(full), [7]);
        assert_eq!((full.lo, full.hi), ([1; 3], [1; 3]));
        assert_eq!((full.reach_lo, full.reach_hi), ([0; 3], [3; 3]));
        for c in &merged.cells {
            assert!((0..3).all(|a| c.reach_lo[a] <= c.lo[a] && c.hi[a] <= c.reach_hi[a]));
        }
    }

    /// Two voxels holding the same triangle merge into one cell that stores it once; two
    /// voxels full of different triangles stay apart.
    #[test]
    fn a_shared_triangle_is_stored_once_and_full_cells_stay_apart() {
        let r = UVec3::new(2, 1, 1);
        let merged = merge_voxels(r, Vec3::ONE, &[0, 1, 2], vec![5, 5], 1.0);
        assert_eq!(merged.cells.len(), 1);
        assert_eq!(merged.triangles(&merged.cells[0]), [5]);
        let pool: Vec<u32> = (0..16).collect();
        let merged = merge_voxels(r, Vec3::ONE, &[0, 8, 16], pool, 1.0);
        assert_eq!(merged.cells.len(), 2);
        assert_eq!(merged.cells[0].reach_hi, [0, 0, 0]);
    }
}
