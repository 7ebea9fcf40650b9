//! PROTOTYPE: an irregular grid (Pérard-Gayot, Kalojanov & Slusallek 2017, "GPU ray
//! tracing using irregular grids") over a built grid's cells: neighbouring cells merged
//! when a surface-area cost says so, then each cell's box expanded over neighbours whose
//! triangles it already holds, so a ray takes one lookup and one exit per cell.

use glam::{IVec3, UVec3, Vec3, Vec3A};

use super::block::{Block, LANES};
use super::cells::Lookup;
use super::{Grid, GridHit};
use crate::accel::frame::GridFrame;
use crate::accel::{Ray, Triangle};

/// One cell of the irregular grid: its (expanded) box in fine-cell units and its blocks.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
struct Cell {
    lo: [u16; 3],
    hi: [u16; 3],
    first: u32,
}

/// Knobs of the build.
#[derive(Clone, Copy, Debug)]
pub struct IrregularParams {
    /// Cost of a step relative to a block test.
    pub step_cost: f32,
    /// Most layers a box grows by on each face.
    pub expand_limit: u32,
    /// Merge cells at all.
    pub merge: bool,
}

impl Default for IrregularParams {
    fn default() -> Self {
        IrregularParams {
            step_cost: 1.0,
            expand_limit: 64,
            merge: true,
        }
    }
}

/// Figures of a built irregular grid.
#[derive(Clone, Copy, Debug)]
pub struct IrregularStats {
    /// Cells.
    pub cells: usize,
    /// Cells without triangles.
    pub empty_cells: usize,
    /// Blocks.
    pub blocks: usize,
    /// Triangle references.
    pub references: usize,
    /// Bytes of map, cells and blocks.
    pub bytes: usize,
}

/// An irregular grid over one mesh.
#[derive(Clone, Debug)]
pub struct IrregularGrid {
    frame: GridFrame,
    /// Per macrocell (8³ fine cells): a cell number, or `NODE |` a node of `nodes`.
    top: Vec<u32>,
    /// Octree nodes below macrocells: eight entries like `top`'s, for the octants.
    nodes: Vec<[u32; 8]>,
    /// With `FLAT`: 512 cell numbers per macrocell of several cells.
    tables: Vec<u32>,
    macro_resolution: UVec3,
    cells: Vec<Cell>,
    blocks: Vec<Block>,
    references: usize,
    empty_cells: usize,
}

struct Work {
    lo: [u32; 3],
    hi: [u32; 3],
    refs: Vec<u32>,
    alive: bool,
}

fn union(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

fn subset(a: &[u32], b: &[u32]) -> bool {
    if a.len() > b.len() {
        return false;
    }
    let mut j = 0;
    for &x in a {
        while j < b.len() && b[j] < x {
            j += 1;
        }
        if j == b.len() || b[j] != x {
            return false;
        }
        j += 1;
    }
    true
}

impl IrregularGrid {
    /// Builds the irregular grid from `grid`'s cells.
    pub fn from_grid(grid: &Grid, params: IrregularParams) -> IrregularGrid {
        let r = grid.frame.resolution;
        let n = grid.frame.cell_count();
        let index = |c: [u32; 3]| (c[0] + r.x * (c[1] + r.y * c[2])) as usize;
        let mut triangles: Vec<Option<Triangle>> = vec![None; grid.triangle_count];
        for b in &grid.blocks {
            for l in 0..LANES {
                if let Some((t, id)) = b.get(l) {
                    triangles[id as usize] = Some(t);
                }
            }
        }
        let mut work: Vec<Work> = Vec::with_capacity(n);
        for z in 0..r.z {
            for y in 0..r.y {
                for x in 0..r.x {
                    let c = UVec3::new(x, y, z);
                    let mut refs = Vec::new();
                    if let Lookup::Blocks(range) = grid.cells.lookup(c.as_ivec3(), 0) {
                        for b in &grid.blocks[range] {
                            for l in 0..LANES {
                                if let Some((_, id)) = b.get(l) {
                                    refs.push(id);
                                }
                            }
                        }
                        refs.sort_unstable();
                    }
                    work.push(Work {
                        lo: [x, y, z],
                        hi: [x + 1, y + 1, z + 1],
                        refs,
                        alive: true,
                    });
                }
            }
        }
        let mut owner: Vec<u32> = (0..n as u32).collect();
        let size = grid.frame.cell_size;
        let cost = |lo: [u32; 3], hi: [u32; 3], refs: usize| {
            let e = Vec3::new(
                (hi[0] - lo[0]) as f32,
                (hi[1] - lo[1]) as f32,
                (hi[2] - lo[2]) as f32,
            ) * size;
            let area = e.x * e.y + e.y * e.z + e.z * e.x;
            area * (params.step_cost + refs.div_ceil(LANES) as f32)
        };
        if params.merge {
            // Buddy merges, one axis at a time, each cell with the same-sized cell beside it
            // when its start is a multiple of twice its size: cells stay near-cubic.
            loop {
                let mut merged_any = false;
                for axis in 0..3 {
                    for start in 0..n {
                        let i = owner[start] as usize;
                        if !work[i].alive || index(work[i].lo) != start {
                            continue;
                        }
                        let s = work[i].hi[axis] - work[i].lo[axis];
                        if work[i].lo[axis] % (2 * s) != 0 {
                            continue;
                        }
                        let mut q = work[i].lo;
                        q[axis] = work[i].hi[axis];
                        if q[axis] >= r[axis] {
                            continue;
                        }
                        let j = owner[index(q)] as usize;
                        let (a, b) = (&work[i], &work[j]);
                        let matches = (0..3).all(|k| {
                            if k == axis {
                                b.lo[k] == a.hi[k] && b.hi[k] - b.lo[k] == s
                            } else {
                                a.lo[k] == b.lo[k] && a.hi[k] == b.hi[k]
                            }
                        });
                        if !matches {
                            continue;
                        }
                        let refs = union(&a.refs, &b.refs);
                        let mut hi = a.hi;
                        hi[axis] = b.hi[axis];
                        let merged = cost(a.lo, hi, refs.len());
                        let apart = cost(a.lo, a.hi, a.refs.len()) + cost(b.lo, b.hi, b.refs.len());
                        if merged > apart {
                            continue;
                        }
                        let (blo, bhi) = (b.lo, b.hi);
                        for z in blo[2]..bhi[2] {
                            for y in blo[1]..bhi[1] {
                                for x in blo[0]..bhi[0] {
                                    owner[index([x, y, z])] = i as u32;
                                }
                            }
                        }
                        work[j].alive = false;
                        work[j].refs = Vec::new();
                        work[i].refs = refs;
                        work[i].hi = hi;
                        merged_any = true;
                    }
                }
                if !merged_any {
                    break;
                }
            }
        }
        // Occupied fine cells, summed over boxes from the origin: empty boxes in O(1).
        let (sx, sy) = (r.x as usize + 1, r.y as usize + 1);
        let mut sums = vec![0u32; sx * sy * (r.z as usize + 1)];
        for z in 0..r.z as usize {
            for y in 0..r.y as usize {
                for x in 0..r.x as usize {
                    let full = !work[owner[index([x as u32, y as u32, z as u32])] as usize]
                        .refs
                        .is_empty();
                    let at = |x: usize, y: usize, z: usize| x + sx * (y + sy * z);
                    sums[at(x + 1, y + 1, z + 1)] = u32::from(full)
                        + sums[at(x, y + 1, z + 1)]
                        + sums[at(x + 1, y, z + 1)]
                        + sums[at(x + 1, y + 1, z)]
                        - sums[at(x, y, z + 1)]
                        - sums[at(x, y + 1, z)]
                        - sums[at(x + 1, y, z)]
                        + sums[at(x, y, z)];
                }
            }
        }
        let occupied_in = |lo: [u32; 3], hi: [u32; 3]| {
            let at = |x: u32, y: u32, z: u32| sums[x as usize + sx * (y as usize + sy * z as usize)];
            at(hi[0], hi[1], hi[2]) - at(lo[0], hi[1], hi[2]) - at(hi[0], lo[1], hi[2])
                - at(hi[0], hi[1], lo[2])
                + at(lo[0], lo[1], hi[2])
                + at(lo[0], hi[1], lo[2])
                + at(hi[0], lo[1], lo[2])
                - at(lo[0], lo[1], lo[2])
        };
        // Expansion, then compaction.
        let mut renumber = vec![u32::MAX; n];
        let mut cells = Vec::new();
        let mut blocks = Vec::new();
        let mut references = 0;
        let mut empty_cells = 0;
        for i in 0..n {
            if !work[i].alive {
                continue;
            }
            let w = &work[i];
            let (mut lo, mut hi) = (w.lo, w.hi);
            let mut open = [true; 6];
            for _ in 0..params.expand_limit {
                let mut grew = false;
                for face in 0..6 {
                    if !open[face] {
                        continue;
                    }
                    let axis = face / 2;
                    let (mut llo, mut lhi) = (lo, hi);
                    if face % 2 == 0 {
                        if lo[axis] == 0 {
                            open[face] = false;
                            continue;
                        }
                        llo[axis] = lo[axis] - 1;
                        lhi[axis] = lo[axis];
                    } else {
                        if hi[axis] == r[axis] {
                            open[face] = false;
                            continue;
                        }
                        llo[axis] = hi[axis];
                        lhi[axis] = hi[axis] + 1;
                    }
                    let ok = if occupied_in(llo, lhi) == 0 {
                        true
                    } else if w.refs.is_empty() {
                        false
                    } else {
                        let mut ok = true;
                        let mut last = u32::MAX;
                        'layer: for z in llo[2]..lhi[2] {
                            for y in llo[1]..lhi[1] {
                                for x in llo[0]..lhi[0] {
                                    let o = owner[index([x, y, z])];
                                    if o == last || o as usize == i {
                                        continue;
                                    }
                                    last = o;
                                    if !subset(&work[o as usize].refs, &w.refs) {
                                        ok = false;
                                        break 'layer;
                                    }
                                }
                            }
                        }
                        ok
                    };
                    if ok {
                        lo = lo.min_of(llo);
                        hi = hi.max_of(lhi);
                        grew = true;
                    } else {
                        open[face] = false;
                    }
                }
                if !grew {
                    break;
                }
            }
            renumber[i] = cells.len() as u32;
            let first = blocks.len() as u32;
            for chunk in w.refs.chunks(LANES) {
                let mut b = Block::EMPTY;
                for (l, &t) in chunk.iter().enumerate() {
                    b.set(l, &triangles[t as usize].unwrap(), t);
                }
                blocks.push(b);
            }
            references += w.refs.len();
            empty_cells += usize::from(w.refs.is_empty());
            let f = |v: [u32; 3]| [v[0] as u16, v[1] as u16, v[2] as u16];
            cells.push(Cell {
                lo: f(lo),
                hi: f(hi),
                first,
            });
        }
        cells.push(Cell {
            lo: [0; 3],
            hi: [0; 3],
            first: blocks.len() as u32,
        });
        let map: Vec<u32> = owner.iter().map(|&o| renumber[o as usize]).collect();
        let m = (r + UVec3::splat(7)) / 8;
        let mut nodes = Vec::new();
        let mut tables = Vec::new();
        let mut top = Vec::with_capacity((m.x * m.y * m.z) as usize);
        for z in 0..m.z {
            for y in 0..m.y {
                for x in 0..m.x {
                    let entry = octree(&map, r, UVec3::new(x, y, z) * 8, 8, &mut nodes);
                    if FLAT && entry & NODE != 0 {
                        let k = tables.len() / 512;
                        for l in 0..512u32 {
                            let c = UVec3::new(x, y, z) * 8 + UVec3::new(l & 7, (l >> 3) & 7, l >> 6);
                            let c = c.min(r - 1);
                            tables.push(map[(c.x + r.x * (c.y + r.y * c.z)) as usize]);
                        }
                        top.push(NODE | k as u32);
                    } else {
                        top.push(entry);
                    }
                }
            }
        }
        IrregularGrid {
            frame: grid.frame,
            top,
            nodes: if FLAT { Vec::new() } else { nodes },
            tables,
            macro_resolution: m,
            cells,
            blocks,
            references,
            empty_cells,
        }
    }

    /// Figures of the structure.
    pub fn stats(&self) -> IrregularStats {
        IrregularStats {
            cells: self.cells.len(),
            empty_cells: self.empty_cells,
            blocks: self.blocks.len(),
            references: self.references,
            bytes: std::mem::size_of_val(self.top.as_slice())
                + std::mem::size_of_val(self.nodes.as_slice())
                + std::mem::size_of_val(self.tables.as_slice())
                + std::mem::size_of_val(self.cells.as_slice())
                + std::mem::size_of_val(self.blocks.as_slice()),
        }
    }

    /// The closest hit along `ray`; `steps` counts cells visited.
    pub fn intersect(&self, ray: &Ray, steps: &mut u64) -> Option<GridHit> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: checked just above.
            return unsafe { self.intersect_avx2::<true>(ray, steps, 0.0) };
        }
        self.intersect_portable::<true>(ray, steps, 0.0)
    }

    /// The walk alone, stopping where a hit at `t_stop` would stop it.
    pub fn walk(&self, ray: &Ray, steps: &mut u64, t_stop: f32) -> Option<GridHit> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: checked just above.
            return unsafe { self.intersect_avx2::<false>(ray, steps, t_stop) };
        }
        self.intersect_portable::<false>(ray, steps, t_stop)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn intersect_avx2<const TEST: bool>(
        &self,
        ray: &Ray,
        steps: &mut u64,
        t_stop: f32,
    ) -> Option<GridHit> {
        self.intersect_portable::<TEST>(ray, steps, t_stop)
    }

    #[inline(always)]
    fn intersect_portable<const TEST: bool>(
        &self,
        ray: &Ray,
        steps: &mut u64,
        t_stop: f32,
    ) -> Option<GridHit> {
        let walk = self.frame.start_walk(ray)?;
        let up = walk.up.cmpne(Vec3A::ZERO);
        let moving = walk.moving.cmpne(Vec3A::ZERO);
        let resolution_f = self.frame.resolution.as_vec3a();
        let mut c = walk.cell;
        let mut c_f = c.as_vec3a();
        let mut nearest: Option<GridHit> = None;
        let mut t_nearest = if TEST { ray.t_max } else { t_stop };
        loop {
            *steps += 1;
            let id = self.lookup(c);
            let cell = &self.cells[id];
            let end = self.cells[id + 1].first;
            let lo = Vec3A::new(cell.lo[0] as f32, cell.lo[1] as f32, cell.lo[2] as f32);
            let hi = Vec3A::new(cell.hi[0] as f32, cell.hi[1] as f32, cell.hi[2] as f32);
            let face = Vec3A::select(up, hi, lo);
            let t = walk.slope * face + walk.offset;
            let on_x = (t.x <= t.y) & (t.x <= t.z);
            let on_y = !on_x & (t.y <= t.z);
            let on_z = !on_x & !on_y;
            let t_exit = t.x.min(t.y).min(t.z);
            let chosen = glam::BVec3A::new(on_x, on_y, on_z);
            let next = Vec3A::select(up, hi, lo - Vec3A::ONE);
            let under = ((Vec3A::splat(t_exit) - walk.offset) * walk.cells_per_t).floor();
            let side = under.clamp(lo, hi - Vec3A::ONE);
            let side = Vec3A::select(up, side.max(c_f), side.min(c_f));
            let landed = Vec3A::select(chosen, next, Vec3A::select(moving, side, c_f));
            let blocks = &self.blocks[cell.first as usize..end as usize];
            if TEST && !blocks.is_empty() {
                // Look ahead: the next cell's record and its first blocks, asked for now.
                let beyond_now = next.cmplt(Vec3A::ZERO) | next.cmpge(resolution_f);
                if !(beyond_now & chosen).any() {
                    let n = landed;
                    let id = self.lookup(IVec3::new(n.x as i32, n.y as i32, n.z as i32));
                    let f = self.cells[id].first as usize;
                    if f < self.blocks.len() {
                        crate::accel::prefetch::prefetch(&self.blocks[f]);
                    }
                }
                for b in blocks {
                    crate::accel::prefetch::prefetch(b);
                }
            }
            if !TEST {
                *steps += 1000 * u64::from(!blocks.is_empty());
            }
            for block in blocks.iter().filter(|_| TEST) {
                if let Some(hit) = block.nearest(ray, t_nearest) {
                    t_nearest = hit.t;
                    nearest = Some(hit.into());
                }
            }
            let beyond = next.cmplt(Vec3A::ZERO) | next.cmpge(resolution_f);
            if (t_nearest <= t_exit) | (t_exit >= walk.t_end) | (beyond & chosen).any() {
                return nearest;
            }
            c_f = landed;
            c = IVec3::new(landed.x as i32, landed.y as i32, landed.z as i32);
        }
    }
}

/// Marks an entry of `top` or `nodes` that is a node, not a cell.
const NODE: u32 = 1 << 31;
/// Flat 512-entry tables instead of the octree below macrocells.
const FLAT: bool = true;

impl IrregularGrid {
    /// The cell holding fine cell `c`.
    #[inline(always)]
    fn lookup(&self, c: IVec3) -> usize {
        let u = c.as_uvec3();
        let m = u >> 3u32;
        let mr = self.macro_resolution;
        let mut e = self.top[(m.x + mr.x * (m.y + mr.y * m.z)) as usize];
        if FLAT {
            if e & NODE != 0 {
                let l = (u.x & 7) | ((u.y & 7) << 3) | ((u.z & 7) << 6);
                e = self.tables[(e & !NODE) as usize * 512 + l as usize];
            }
            return e as usize;
        }
        let mut shift = 2;
        while e & NODE != 0 {
            let o = ((u.x >> shift) & 1) | (((u.y >> shift) & 1) << 1) | (((u.z >> shift) & 1) << 2);
            e = self.nodes[(e & !NODE) as usize][o as usize];
            shift -= 1;
        }
        e as usize
    }
}

/// The entry for the cube of `size` fine cells at `origin`: its cell if one holds all of it.
fn octree(map: &[u32], r: UVec3, origin: UVec3, size: u32, nodes: &mut Vec<[u32; 8]>) -> u32 {
    let hi = (origin + UVec3::splat(size)).min(r);
    let mut first = None;
    let mut uniform = true;
    'all: for z in origin.z..hi.z {
        for y in origin.y..hi.y {
            for x in origin.x..hi.x {
                let id = map[(x + r.x * (y + r.y * z)) as usize];
                match first {
                    None => first = Some(id),
                    Some(f) if f != id => {
                        uniform = false;
                        break 'all;
                    }
                    _ => {}
                }
            }
        }
    }
    if uniform || size == 1 {
        return first.unwrap_or(0);
    }
    let k = nodes.len();
    nodes.push([0; 8]);
    let half = size / 2;
    for o in 0..8u32 {
        let child = origin + UVec3::new(o & 1, (o >> 1) & 1, o >> 2) * half;
        nodes[k][o as usize] = octree(map, r, child, half, nodes);
    }
    NODE | k as u32
}

trait MinMax {
    fn min_of(self, o: Self) -> Self;
    fn max_of(self, o: Self) -> Self;
}

impl MinMax for [u32; 3] {
    fn min_of(self, o: Self) -> Self {
        [self[0].min(o[0]), self[1].min(o[1]), self[2].min(o[2])]
    }
    fn max_of(self, o: Self) -> Self {
        [self[0].max(o[0]), self[1].max(o[1]), self[2].max(o[2])]
    }
}
