//! Grid construction: resolution, then count → prefix sums → fill into compact storage.

pub(in crate::accel::grid) mod block_order;
pub(in crate::accel::grid) mod box_counts;
pub(in crate::accel::grid) mod cell_blocks;
pub(in crate::accel::grid) mod cell_order;
pub(in crate::accel::grid) mod density;
pub(in crate::accel::grid) mod mesh_triangles;
pub(in crate::accel::grid) mod overlap;

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::Grid;
use crate::accel::grid::storage::block::{Block, LANES};
use crate::accel::grid::storage::cell_box::{self, Kept};
use crate::accel::grid::storage::cells::CellIndex;
use crate::accel::grid::storage::macrocell::MACRO_CELLS;
use cell_blocks::{BlockBoxes, CellRun};
use cell_order::{Buckets, CellOrder, KeyParts};
use mesh_triangles::MeshTriangles;
use overlap::{Polygon, TriangleBoxTest};

use crate::accel::Triangle;
use crate::accel::grid::frame::{GridFrame, padded, resolution};
#[cfg(target_arch = "x86_64")]
use crate::accel::isa::{Kernel, X86Level, dispatch};
use crate::geometry::Aabb;

/// Which grids keep boxes per cell and per block ([`cell_box`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Boxes {
    /// Those whose blocks outgrow the caches ([`cell_box::boxes_for`]).
    BySize,
    /// Every grid (for tests).
    #[cfg_attr(not(test), allow(dead_code))]
    Always,
}

/// Meshes of at most this many triangles (two blocks) get a single cell: a wall, a box.
pub(in crate::accel::grid) const SINGLE_CELL_MAX: usize = 2 * LANES;

/// Bounding boxes of at most this many cells are tested cell by cell; larger ones are
/// walked slab by slab (clipping costs more than it saves on a few cells).
const SMALL_BOX_CELLS: u64 = 64;

impl Grid {
    /// Builds a grid over a triangle soup, with the density chosen for it ([`density`]).
    pub fn build(triangles: Vec<Triangle>) -> Grid {
        let (vertices, indices) = soup(&triangles);
        Grid::build_mesh(vertices, &indices, None, Boxes::BySize)
    }

    /// Builds a grid over a triangle soup with about `density` cells per triangle.
    pub fn build_with_density(triangles: Vec<Triangle>, density: f32) -> Grid {
        let (vertices, indices) = soup(&triangles);
        Grid::build_mesh(vertices, &indices, Some(density), Boxes::BySize)
    }

    /// Builds a grid over an indexed mesh, with the density chosen for it ([`density`]).
    ///
    /// Degenerate triangles (no area, non-finite corners, or corners past the vertex array)
    /// go into no cell and so are never hit; hits report indices into `indices`.
    pub fn from_mesh(vertices: Vec<Vec3>, indices: &[[u32; 3]]) -> Grid {
        Grid::build_mesh(vertices, indices, None, Boxes::BySize)
    }

    /// Builds a grid over an indexed mesh with about `density` cells per triangle.
    pub fn from_mesh_with_density(vertices: Vec<Vec3>, indices: &[[u32; 3]], density: f32) -> Grid {
        Grid::build_mesh(vertices, indices, Some(density), Boxes::BySize)
    }

    /// Builds a grid over a triangle soup with about `density` cells per triangle, keeping
    /// boxes whatever its size (for tests: only large grids keep them otherwise).
    #[cfg(test)]
    pub(in crate::accel::grid) fn build_boxed(triangles: Vec<Triangle>, density: f32) -> Grid {
        let (vertices, indices) = soup(&triangles);
        Grid::build_mesh(vertices, &indices, Some(density), Boxes::Always)
    }

    /// [`Grid::from_mesh_with_density`], the density chosen for the mesh when `None`.
    fn build_mesh(
        vertices: Vec<Vec3>,
        indices: &[[u32; 3]],
        density: Option<f32>,
        boxes: Boxes,
    ) -> Grid {
        let triangles = MeshTriangles::new(&vertices, indices);
        // The live triangles' numbers, bounds and summed sizes, chunk by chunk, joined in
        // order (so the sums are the same on any thread count; bounds are exact minima and
        // maxima).
        const CHUNK: usize = 16384;
        let parts: Vec<(Vec<u32>, Aabb, Sizes)> = (0..indices.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let range = c * CHUNK..((c + 1) * CHUNK).min(indices.len());
                let mut live = Vec::with_capacity(range.len());
                let mut bounds = Aabb::EMPTY;
                let mut sizes = Sizes::default();
                for t in range {
                    if let Some(triangle) = triangles.live(t) {
                        live.push(t as u32);
                        bounds = bounds.union(triangle.bounds());
                        sizes.add(&Sizes::of(&triangle));
                    }
                }
                (live, bounds, sizes)
            })
            .collect();
        let live: Vec<u32> = parts.iter().flat_map(|(l, ..)| l.iter().copied()).collect();
        let tight = parts.iter().fold(Aabb::EMPTY, |b, (_, p, _)| b.union(*p));
        let mut sizes = Sizes::default();
        for (.., part) in &parts {
            sizes.add(part);
        }
        let (bounds, resolution) = if tight.is_empty() {
            (
                Aabb {
                    min: Vec3::ZERO,
                    max: Vec3::ONE,
                },
                UVec3::ONE,
            )
        } else {
            let bounds = padded(tight);
            // A few triangles are tested faster all at once than found by walking cells.
            let wanted = if live.len() <= SINGLE_CELL_MAX {
                UVec3::ONE
            } else {
                let density =
                    density.unwrap_or_else(|| density::density_for(bounds, triangles, &live));
                resolution(bounds.extent(), live.len(), density)
            };
            (
                bounds,
                within_reference_budget(wanted, bounds, triangles, &live, &sizes),
            )
        };
        let mut grid = Grid {
            frame: GridFrame::new(bounds, resolution),
            cells: CellIndex::default(),
            blocks: Vec::new(),
            block_boxes: Vec::new(),
            references: 0,
            triangle_count: indices.len(),
            inserted: live.len(),
        };
        // The estimate above keeps references far below 2^32; should it ever be wrong,
        // halve the resolution rather than overflow the 32-bit offsets.
        while !grid.insert(triangles, &live, boxes) {
            grid.frame = GridFrame::new(
                grid.frame.bounds,
                (grid.frame.resolution / 2).max(UVec3::ONE),
            );
        }
        grid
    }

    /// Fills the compact storage: the overlap tests run once, in parallel over chunks of
    /// triangles, giving (cell, triangle) pairs in triangle order; a counting sort by cell
    /// ([`cell_order`], in parallel over parts of the grid) lays them out in cell order, and
    /// the blocks are then written cell by cell, in parallel, straight into their final place
    /// ([`cell_blocks`]; no pass over the whole block array before it is filled), while the
    /// index is built. Within a cell, triangles keep mesh order (in a grid that keeps boxes
    /// per block, Morton order with ties in mesh order, [`block_order`]) whatever the thread
    /// count, so ties between equal hits resolve the same way. False, with nothing changed,
    /// if there are more references than 32-bit offsets hold.
    fn insert(&mut self, triangles: MeshTriangles, live: &[u32], boxes: Boxes) -> bool {
        let m = CellIndex::macro_resolution_for(self.frame.resolution);
        let keys = (m.x * m.y * m.z) as usize * MACRO_CELLS;
        let parts = KeyParts::new(keys);
        let chunks: Vec<Buckets> = live
            .par_chunks(4096)
            .map(|chunk| self.pairs_of(chunk, triangles, &parts))
            .collect();
        let references: usize = chunks.iter().flatten().map(Vec::len).sum();
        if references >= u32::MAX as usize && self.frame.resolution != UVec3::ONE {
            return false;
        }
        let CellOrder { counts, sorted } = parts.sort(&chunks, keys);
        drop(chunks);
        let runs = cell_runs(m, &counts);
        let block_count: usize = runs.iter().map(CellRun::blocks).sum();
        // Boxes per cell and per block ([`cell_box`]) for a grid whose blocks outgrow the
        // caches, each block's found as it is written, while its triangles are at hand; the
        // triangles of its cells of more than one block in Morton order ([`block_order`]).
        let kept = match boxes {
            Boxes::BySize => cell_box::boxes_for(block_count * std::mem::size_of::<Block>()),
            Boxes::Always => Kept::CellsAndBlocks,
        };
        let margin = cell_box::margin_for(&self.frame).filter(|_| kept != Kept::None);
        let masked = margin.is_some() && kept == Kept::CellsAndBlocks;
        let block_boxes = match (margin, masked) {
            (None, _) => BlockBoxes::None,
            (Some(_), false) => BlockBoxes::Words,
            (Some(_), true) => BlockBoxes::OrderedWords,
        };
        // The index and the blocks depend only on the counts and the sorted triangles: each
        // fills the other's idle moments.
        let (cells, (blocks, words)) = rayon::join(
            || {
                CellIndex::build(
                    self.frame.resolution,
                    &counts,
                    LANES as u32,
                    std::mem::size_of::<Block>(),
                )
            },
            || cell_blocks::write(&self.frame, &runs, &sorted, triangles, block_boxes),
        );
        debug_assert_eq!(blocks.len(), cells.block_count());
        drop((runs, sorted, counts));
        self.cells = cells;
        self.blocks = blocks;
        self.references = references;
        if let Some(margin) = margin {
            let boxes = (0..self.cells.occupied())
                .map(|k| cell_box::join_all(&words[self.cells.blocks_of(k)]))
                .collect();
            self.cells.set_cell_boxes(boxes, margin);
        }
        if masked {
            self.block_boxes = words;
        }
        true
    }

    /// Every block's box word within its cell, found from the written blocks (for tests: the
    /// build finds them as it writes the blocks).
    #[cfg(test)]
    pub(in crate::accel::grid) fn block_box_words(&self) -> Vec<u32> {
        let cells = self.cells.occupied_cells();
        let mut words = vec![0; self.blocks.len()];
        for (k, &c) in cells.iter().enumerate() {
            for b in self.cells.blocks_of(k) {
                words[b] = cell_box::block_word(&self.frame, c, &self.blocks[b]);
            }
        }
        words
    }

    /// Every occupied cell's box word, in the order the cells are numbered, found from the
    /// written blocks (for tests: the build finds them as it writes the blocks).
    #[cfg(test)]
    pub(in crate::accel::grid) fn cell_boxes(&self) -> Vec<u32> {
        let cells = self.cells.occupied_cells();
        cells
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                let triangles = self.blocks[self.cells.blocks_of(k)]
                    .iter()
                    .flat_map(|block| {
                        (0..LANES).filter_map(|lane| block.get(lane).map(|(triangle, _)| triangle))
                    });
                cell_box::join_all(&[cell_box::triangles_word(&self.frame, c, triangles)])
            })
            .collect()
    }

    /// The (cell, triangle) pairs of the live triangles numbered in `chunk`, in triangle
    /// order, in the buckets of `parts`.
    fn pairs_of(&self, chunk: &[u32], triangles: MeshTriangles, parts: &KeyParts) -> Buckets {
        let work = PairsOf {
            grid: self,
            chunk,
            triangles,
            parts,
        };
        dispatch(X86Level::Avx2, work)
    }

    #[inline(always)]
    fn pairs_of_portable(
        &self,
        chunk: &[u32],
        triangles: MeshTriangles,
        parts: &KeyParts,
    ) -> Buckets {
        let mut buckets = parts.buckets();
        for &t in chunk {
            self.for_each_overlapped_cell(&triangles.get(t), |cell| {
                parts.push(&mut buckets, cell, t)
            });
        }
        buckets
    }

    /// Calls `f` with the storage key of every cell the triangle overlaps.
    #[inline(always)]
    fn for_each_overlapped_cell(&self, tri: &Triangle, mut f: impl FnMut(usize)) {
        let pad = self.frame.pad();
        let (lo, hi) = self.frame.cells_of_box(&tri.bounds());
        let span = hi - lo + UVec3::ONE;
        // A box one cell thick on two axes is a row of cells, and the triangle, a connected
        // set spanning the row, touches every one of them: no test needed (40 % of the
        // dragon's triangles, and every one inside a single cell).
        if (span.cmpgt(UVec3::ONE).bitmask()).count_ones() <= 1 {
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        f(self.storage_key(UVec3::new(x, y, z)));
                    }
                }
            }
            return;
        }
        let half = 0.5 * self.frame.cell_size + pad;
        let vertices = tri.vertices();
        let test = TriangleBoxTest::new(vertices, half);
        // Most triangles span a few cells: test every cell of the bounding box.
        if span.x as u64 * span.y as u64 * span.z as u64 <= SMALL_BOX_CELLS {
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        self.report_if_overlapped(&test, UVec3::new(x, y, z), &mut f);
                    }
                }
            }
            return;
        }
        // Walk slab by slab, row by row, clipping the triangle to each, so only cells near
        // it are tested: a long thin triangle across the grid costs its overlap, not the
        // volume of its bounding box (found by hostile testing: a 100k-corner fan took
        // minutes). Slabs and rows are padded like the cells, so clipping never loses one.
        let slab = |axis: usize, i: u32| {
            let lo =
                self.frame.bounds.min[axis] + i as f32 * self.frame.cell_size[axis] - pad[axis];
            (lo, lo + self.frame.cell_size[axis] + 2.0 * pad[axis])
        };
        let triangle = Polygon::from_triangle(vertices);
        for z in lo.z..=hi.z {
            let (z0, z1) = slab(2, z);
            let in_slab = triangle.clip(2, z0, z1);
            let Some(slab_bounds) = in_slab.bounds() else {
                continue;
            };
            let rows = self.frame.cell_of(slab_bounds.min - pad).y
                ..=self.frame.cell_of(slab_bounds.max + pad).y;
            for y in rows {
                let (y0, y1) = slab(1, y);
                let Some(row_bounds) = in_slab.clip(1, y0, y1).bounds() else {
                    continue;
                };
                let first = self.frame.cell_of(row_bounds.min - pad).x;
                let last = self.frame.cell_of(row_bounds.max + pad).x;
                for x in first..=last {
                    self.report_if_overlapped(&test, UVec3::new(x, y, z), &mut f);
                }
            }
        }
    }

    /// Calls `f` with cell `c`'s index if the triangle of `test` overlaps it (grown by the
    /// pad the test was made with).
    #[inline(always)]
    fn report_if_overlapped(&self, test: &TriangleBoxTest, c: UVec3, f: &mut impl FnMut(usize)) {
        let center = self.frame.bounds.min + (c.as_vec3() + 0.5) * self.frame.cell_size;
        if test.overlaps(center) {
            f(self.storage_key(c));
        }
    }
}

/// The vertices and indices of a triangle soup, three corners per triangle.
pub(in crate::accel::grid) fn soup(triangles: &[Triangle]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let vertices = triangles.iter().flat_map(|t| t.vertices()).collect();
    let indices = (0..triangles.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    (vertices, indices)
}

/// The occupied cells' runs of the cell-sorted triangle numbers, in key order as the index
/// numbers them, from the triangles per key `counts` (empty macrocells, most of the grid,
/// are passed over whole).
fn cell_runs(m: UVec3, counts: &[u32]) -> Vec<CellRun> {
    let mut runs = Vec::new();
    let mut start = 0u32;
    for (mi, macrocell) in counts.chunks(MACRO_CELLS).enumerate() {
        if macrocell.iter().all(|&n| n == 0) {
            continue;
        }
        for (l, &count) in macrocell.iter().enumerate().filter(|(_, n)| **n != 0) {
            let cell = CellIndex::cell_at(m, mi, l);
            runs.push(CellRun { start, count, cell });
            start += count;
        }
    }
    runs
}

/// Most references (cell, triangle pairs) the build may make per triangle on average, and in
/// all: long thin triangles across a fine grid (a fan of 100k slivers) would otherwise
/// make hundreds each, and more than 2^32 would overflow the offsets.
const REFERENCES_PER_TRIANGLE: f64 = 32.0;
const MAX_REFERENCES: f64 = (1u64 << 31) as f64;

/// `wanted`, made coarser until the estimated references fit the budget. A triangle of
/// area A and perimeter P overlaps about √3·A/s² + 2·P/s + 1 cells of side s (the cells its
/// surface and its edges pass through), and never more than its bounding box holds.
/// The live triangles (numbered in `live`; the others make no references) add up to
/// `sizes`: while the estimate without the bounding-box limit fits (the usual case), no pass
/// over the triangles is needed.
fn within_reference_budget(
    wanted: UVec3,
    bounds: Aabb,
    triangles: MeshTriangles,
    live: &[u32],
    sizes: &Sizes,
) -> UVec3 {
    let budget = reference_budget(sizes.count);
    let mut r = wanted;
    for _ in 0..32 {
        let cell = bounds.extent() / r.as_vec3();
        let s = cell.min_element().max(f32::MIN_POSITIVE) as f64;
        if sizes.cells_met(s) <= budget {
            break;
        }
        let estimate_of = |t: &Triangle| estimated_cells(t, cell);
        // Partial sums over fixed chunks, added in order: the same total on any number of
        // threads, so the same grid.
        let partial: Vec<f64> = live
            .par_chunks(4096)
            .map(|chunk| chunk.iter().map(|&t| estimate_of(&triangles.get(t))).sum())
            .collect();
        let estimate: f64 = partial.iter().sum();
        if estimate <= budget || r == UVec3::ONE {
            break;
        }
        // References grow as 1/s (edges) to 1/s² (surfaces): shrink by the square root.
        let shrink = (budget / estimate).sqrt().clamp(0.25, 0.9) as f32;
        r = (r.as_vec3() * shrink).floor().max(Vec3::ONE).as_uvec3();
    }
    r
}

/// Areas, perimeters and number of triangles, summed: what the estimate of the cells they
/// meet needs.
#[derive(Clone, Copy, Debug, Default)]
struct Sizes {
    area: f64,
    perimeter: f64,
    count: f64,
}

/// References (cell, triangle pairs) allowed for `count` triangles.
fn reference_budget(count: f64) -> f64 {
    (REFERENCES_PER_TRIANGLE * count + (1 << 20) as f64).min(MAX_REFERENCES)
}

/// Cells of size `cell` that triangle `t` meets, by the estimate above.
fn estimated_cells(t: &Triangle, cell: Vec3) -> f64 {
    let reach = t.bounds().extent() / cell + 1.0;
    let boxed = reach.x as f64 * reach.y as f64 * reach.z as f64;
    let s = cell.min_element().max(f32::MIN_POSITIVE) as f64;
    Sizes::of(t).cells_met(s).min(boxed)
}

impl Sizes {
    /// Cells of side `s` met by these triangles, without the bounding-box limit.
    fn cells_met(&self, s: f64) -> f64 {
        3f64.sqrt() * self.area / (s * s) + 2.0 * self.perimeter / s + self.count
    }

    fn of(t: &Triangle) -> Sizes {
        let [a, b, c] = t.vertices();
        Sizes {
            area: 0.5 * (b - a).cross(c - a).length() as f64,
            perimeter: ((b - a).length() + (c - b).length() + (a - c).length()) as f64,
            count: 1.0,
        }
    }

    fn add(&mut self, other: &Sizes) {
        self.area += other.area;
        self.perimeter += other.perimeter;
        self.count += other.count;
    }
}

/// [`Grid::pairs_of_portable`] as a [`Kernel`]: compiled for AVX2, the overlap tests'
/// thirteen axes go in wider lanes and `floor` is one instruction (baseline x86-64 calls a
/// library function). The arithmetic, and so the grid, is the same.
struct PairsOf<'a> {
    grid: &'a Grid,
    chunk: &'a [u32],
    triangles: MeshTriangles<'a>,
    parts: &'a KeyParts,
}

impl Kernel for PairsOf<'_> {
    type Output = Buckets;
    #[inline(always)]
    fn run<const FUSED: bool>(self) -> Buckets {
        self.grid
            .pairs_of_portable(self.chunk, self.triangles, self.parts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sizes_of(triangles: &[Triangle]) -> Sizes {
        let mut sizes = Sizes::default();
        for t in triangles {
            sizes.add(&Sizes::of(t));
        }
        sizes
    }

    /// The reference budget's choice for `triangles` (as an indexed mesh, all live).
    fn budgeted(wanted: UVec3, bounds: Aabb, triangles: &[Triangle]) -> UVec3 {
        let (vertices, indices) = soup(triangles);
        let live: Vec<u32> = (0..triangles.len() as u32).collect();
        let mesh = MeshTriangles::new(&vertices, &indices);
        within_reference_budget(wanted, bounds, mesh, &live, &sizes_of(triangles))
    }

    /// `count` triangles with a corner in the cube [−1, 1]³ and edges of up to the sizes
    /// `sizes`, in turn.
    fn random_triangles(seed: u64, count: usize, sizes: [f32; 4]) -> Vec<Triangle> {
        let mut rng = crate::render::sampling::Rng::new(seed, 5);
        (0..count)
            .map(|k| {
                let mut u = || rng.uniform() * 2.0 - 1.0;
                let a = Vec3::new(u(), u(), u());
                Triangle::new(
                    a,
                    a + Vec3::new(u(), u(), u()) * sizes[k % 4],
                    a + Vec3::new(u(), u(), u()) * sizes[k % 4],
                )
            })
            .collect()
    }

    /// The overlap tests compiled for this processor pair each triangle with exactly the
    /// cells the portable ones give it: triangles of every size and slope, from slivers in
    /// one cell to ones across the grid (walked slab by slab).
    #[test]
    fn the_portable_overlap_tests_find_what_the_fast_ones_find() {
        let triangles = random_triangles(41, 6_000, [0.002, 0.02, 0.3, 1.5]);
        let grid = Grid::build(triangles.clone());
        let (vertices, indices) = soup(&triangles);
        let mesh = MeshTriangles::new(&vertices, &indices);
        let live: Vec<u32> = (0..triangles.len() as u32).collect();
        let m = CellIndex::macro_resolution_for(grid.frame.resolution);
        let parts = KeyParts::new((m.x * m.y * m.z) as usize * MACRO_CELLS);
        let mut pairs = 0;
        for chunk in live.chunks(500) {
            let fast = grid.pairs_of(chunk, mesh, &parts);
            assert_eq!(fast, grid.pairs_of_portable(chunk, mesh, &parts));
            pairs += fast.iter().map(Vec::len).sum::<usize>();
        }
        assert!(pairs > 3 * triangles.len(), "{pairs} pairs");
    }

    /// The build's box words, found lane by lane for each block as it is written (compiled
    /// for this processor and portably), are the words of the triangles' parts found
    /// triangle by triangle, for triangles of every size, most of them crossing their
    /// cells' faces.
    #[test]
    fn the_block_box_words_are_the_triangle_by_triangle_ones() {
        let triangles = random_triangles(47, 4_000, [0.01, 0.03, 0.1, 0.4]);
        // Coarse cells, so that many hold several blocks.
        let grid = Grid::build_with_density(triangles.clone(), 0.5);
        let (vertices, indices) = soup(&triangles);
        let mesh = MeshTriangles::new(&vertices, &indices);
        let expected = grid.cell_boxes();
        let cells = grid.cells.occupied_cells();
        let (mut partial, mut blocks) = (0, 0);
        for (k, &cell) in cells.iter().enumerate() {
            let stored = &grid.blocks[grid.cells.blocks_of(k)];
            let ids: Vec<u32> = stored
                .iter()
                .flat_map(|block| (0..LANES).filter_map(|l| block.get(l)).map(|(_, t)| t))
                .collect();
            let run = CellRun {
                start: 0,
                count: ids.len() as u32,
                cell,
            };
            let fast = cell_blocks::write_cell(&grid.frame, run, &ids, mesh, false);
            assert_eq!(fast.0, stored);
            assert_eq!(
                cell_blocks::write_cell(&grid.frame, run, &ids, mesh, true),
                fast
            );
            assert_eq!(cell_box::join_all(&fast.1), expected[k], "cell {cell}");
            partial += usize::from(expected[k] != cell_box::WHOLE);
            blocks += stored.len();
        }
        // Most boxes are smaller than their cells, and many cells have several blocks.
        assert!(
            partial * 2 > cells.len(),
            "{partial} of {} cells",
            cells.len()
        );
        assert!(blocks > cells.len() + cells.len() / 10, "{blocks} blocks");
    }

    /// A grid that keeps boxes has each block's box word, and the triangles of each of its
    /// cells of several blocks in Morton order: the cell's triangles as in mesh order, each
    /// cell's keys ascending (ties by triangle number), and the blocks' boxes smaller than
    /// in mesh order.
    #[test]
    fn a_boxed_grid_orders_its_crowded_cells_and_keeps_each_blocks_box() {
        // Triangles smaller than the cells, in cells of several blocks each, as on a large
        // scanned mesh.
        let triangles = random_triangles(53, 4_000, [0.01, 0.02, 0.03, 0.05]);
        let boxed = Grid::build_boxed(triangles.clone(), 0.05);
        let plain = Grid::build_with_density(triangles.clone(), 0.05);
        boxed.validate().unwrap();
        assert!(boxed.cells.box_margin().is_some() && plain.cells.box_margin().is_none());
        assert_eq!(boxed.block_boxes, boxed.block_box_words());
        assert_eq!(boxed.cells.occupied_cells(), plain.cells.occupied_cells());
        let ids = |grid: &Grid, k: usize| -> Vec<u32> {
            grid.blocks[grid.cells.blocks_of(k)]
                .iter()
                .flat_map(|block| (0..LANES).filter_map(|l| block.get(l).map(|(_, t)| t)))
                .collect()
        };
        let volume = |words: &[u32]| -> f64 {
            let sides = words.iter().map(|&w| {
                let (lo, hi) = cell_box::decode::<false>(w);
                (hi - lo).max(glam::Vec3A::ZERO)
            });
            sides.map(|s| f64::from(s.x * s.y * s.z)).sum()
        };
        let plain_words = plain.block_box_words();
        let (mut crowded, mut boxed_volume, mut plain_volume) = (0, 0.0, 0.0);
        for (k, &cell) in boxed.cells.occupied_cells().iter().enumerate() {
            let (ordered, mesh_order) = (ids(&boxed, k), ids(&plain, k));
            if mesh_order.len() <= LANES {
                assert_eq!(ordered, mesh_order, "cell {cell}");
                continue;
            }
            crowded += 1;
            let mut sorted = ordered.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, mesh_order, "cell {cell}");
            let keys: Vec<(u32, u32)> = ordered
                .iter()
                .map(|&t| {
                    (
                        block_order::key(&boxed.frame, cell, triangles[t as usize].bounds()),
                        t,
                    )
                })
                .collect();
            assert!(keys.is_sorted(), "cell {cell}: {keys:?}");
            let blocks = boxed.cells.blocks_of(k);
            boxed_volume += volume(&boxed.block_boxes[blocks.clone()]);
            plain_volume += volume(&plain_words[blocks]);
        }
        assert!(crowded > 100, "{crowded} crowded cells");
        assert!(
            boxed_volume < 0.8 * plain_volume,
            "{boxed_volume} against {plain_volume}"
        );
    }

    /// Small triangles keep the resolution asked for (the summed estimate fits at once);
    /// slivers across the whole box make it coarser until the clamped estimate fits.
    #[test]
    fn the_reference_budget_coarsens_only_grids_of_long_triangles() {
        let bounds = Aabb {
            min: Vec3::ZERO,
            max: Vec3::splat(1.0),
        };
        let wanted = UVec3::splat(200);
        let small: Vec<Triangle> = (0..2000)
            .map(|i| {
                let p = Vec3::new((i % 13) as f32, (i % 7) as f32, (i % 11) as f32) / 13.0;
                Triangle::new(p, p + Vec3::X * 0.01, p + Vec3::Y * 0.01)
            })
            .collect();
        let r = budgeted(wanted, bounds, &small);
        assert_eq!(r, wanted);
        let slivers: Vec<Triangle> = (0..2000)
            .map(|i| {
                let y = i as f32 / 2000.0;
                Triangle::new(
                    Vec3::new(0.0, y, 0.0),
                    Vec3::new(1.0, y, 1.0),
                    Vec3::new(1.0, y + 1e-4, 1.0),
                )
            })
            .collect();
        let r = budgeted(wanted, bounds, &slivers);
        assert!(r.x < wanted.x && r.x > 1, "{r}");
        // What was chosen fits the budget by the clamped per-triangle estimate.
        let cell = bounds.extent() / r.as_vec3();
        let estimate: f64 = slivers.iter().map(|t| estimated_cells(t, cell)).sum();
        assert!(estimate <= reference_budget(2000.0));
    }
}
