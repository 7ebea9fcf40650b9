//! The grid of one eye point: a perspective grid (Hunt & Mark 2008, "Ray-specialized
//! acceleration structures for ray tracing") for the rays a pinhole camera sends.
//!
//! Every ray from the eye is one point of the plane one unit ahead of it, so the grid is a
//! 2D array of columns over a window of that plane; a triangle goes into each column its
//! projection's bounds (with a margin for rounding) meet, and a column's triangles are kept
//! nearest first, the columns one after another in blocks of eight. A ray finds its column
//! with a division and two multiplications, then tests the column's blocks until the next
//! block's least depth lies beyond the nearest hit found: no walk, and a ray that misses
//! everything reads one word.
//! The triangles are the grids' own (the numbers their blocks hold, tested by the same
//! [`Block`] arithmetic), so a ray finds the hit the grids find: the same triangle, `t`,
//! `u` and `v`. Where two triangles are hit at exactly the nearest distance (a ray through a
//! shared edge) the order of testing would decide, so the view grid does not answer: such
//! rays, rays not from the eye and rays outside the window are the caller's to ask of the
//! grids, which makes every answer the grids' own by construction.

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;

use super::Grid;
use super::storage::block::{Block, LANES, LaneHit};
use crate::accel::isa::{Kernel, X86Level, dispatch};
use crate::accel::{Ray, Triangle};

/// Relative margin on a projected coordinate: rounding in the projection of corners and of
/// ray directions, and Möller–Trumbore accepting a hit a few ulps outside the triangle,
/// are a few times 1e-7 of the coordinates involved.
const PLANE_MARGIN: f32 = 1e-5;

/// Margin on a triangle's least depth, relative to its distance from the eye: the depth of
/// a hit point found by Möller–Trumbore is within a few ulps of that distance of the
/// triangle's own.
const DEPTH_MARGIN: f32 = 1e-4;

/// A triangle whose nearest corner lies closer to the eye's plane than this share of its
/// distance from the eye projects too widely (or not at all): every ray tests it instead.
const NEAR_SHARE: f32 = 1e-3;

/// Triangles tested by every ray at most; a view with more gets no grid.
const NEAR_MAX: usize = 256;

/// References per triangle past which the columns are made coarser.
const REFERENCES_PER_TRIANGLE: usize = 8;

/// An eye point, the directions it looks along and the window of them the grid covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Where every ray the grid answers starts.
    pub eye: Vec3,
    /// The window's horizontal (a unit vector, as are `up` and `forward`, at right angles).
    pub right: Vec3,
    /// The window's vertical.
    pub up: Vec3,
    /// Ahead: depth is measured along it.
    pub forward: Vec3,
    /// The window's lower corner in the plane one unit ahead, in (`right`, `up`) coordinates.
    pub lo: Vec2,
    /// The window's upper corner.
    pub hi: Vec2,
    /// Columns wanted at most.
    pub max_columns: u32,
}

impl View {
    /// Where the line from the eye along `d` meets the plane one unit ahead, and `d`'s
    /// component ahead; `None` for a direction not ahead of the eye.
    #[inline(always)]
    fn on_plane(&self, d: Vec3) -> Option<(Vec2, f32)> {
        let w = d.dot(self.forward);
        (w > 0.0).then(|| (Vec2::new(d.dot(self.right), d.dot(self.up)) / w, w))
    }
}

/// A closest hit found in a [`ViewGrid`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
    /// Which of the grids the view was built over holds the triangle.
    pub source: u32,
    /// Index of the triangle in that grid's mesh.
    pub triangle: u32,
}

/// The columns of one view and their triangles, nearest first.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewGrid {
    view: View,
    columns: UVec2,
    /// Columns per unit of the plane, horizontally and vertically.
    scale: Vec2,
    /// The first lane of each column, row after row, counting the lanes of all blocks in
    /// turn; one more entry, the end.
    starts: Vec<u32>,
    blocks: Vec<Block>,
    /// The least depth of each block's triangles less a margin ([`fill_columns`]).
    depths: Vec<f32>,
    /// Triangles too near the eye's plane to project ([`NEAR_SHARE`]), for every ray.
    near: Vec<Block>,
    /// The grid and triangle of each lane id.
    owners: Vec<(u32, u32)>,
}

/// Where one triangle goes.
enum Place {
    /// Nowhere: behind the eye or outside the window.
    Nowhere,
    /// Into the list every ray tests.
    Near,
    /// Into the columns its projection's bounds (in the plane, margin included) meet,
    /// at least depth `depth`.
    Columns { lo: Vec2, hi: Vec2, depth: f32 },
}

impl ViewGrid {
    /// The grid of `view` over the triangles of `grids`, each in the space the rays are
    /// in; `None` when too many triangles lie near the eye's plane ([`NEAR_MAX`]).
    pub fn build(grids: &[&Grid], view: View) -> Option<ViewGrid> {
        let triangles: Vec<(Triangle, (u32, u32))> = (grids.iter().enumerate())
            .flat_map(|(g, grid)| {
                (grid.unique_triangles().into_iter()).map(move |(tri, id)| (tri, (g as u32, id)))
            })
            .collect();
        let places: Vec<Place> = triangles
            .par_iter()
            .map(|(tri, _)| place(&view, tri))
            .collect();
        let near_ids: Vec<u32> = (0..places.len() as u32)
            .filter(|&i| matches!(places[i as usize], Place::Near))
            .collect();
        if near_ids.len() > NEAR_MAX {
            return None;
        }
        let placed = places
            .iter()
            .filter(|p| matches!(p, Place::Columns { .. }))
            .count();
        let mut columns = column_counts(&view, placed);
        let ranges = loop {
            let ranges: Vec<Option<[UVec2; 2]>> = places
                .par_iter()
                .map(|p| column_range(&view, columns, p))
                .collect();
            let references: usize = ranges.iter().flatten().map(cells).sum();
            if references <= REFERENCES_PER_TRIANGLE * placed + (columns.x * columns.y) as usize
                || columns == UVec2::ONE
            {
                if references > u32::MAX as usize {
                    return None;
                }
                break ranges;
            }
            columns = (columns / 2).max(UVec2::ONE);
        };
        let owners = triangles.iter().map(|(_, owner)| *owner).collect();
        let near = fill_blocks(near_ids.iter().map(|&i| (&triangles[i as usize].0, i)));
        let (starts, blocks, depths) = fill_columns(&triangles, &places, &ranges, columns);
        Some(ViewGrid {
            scale: scale_of(&view, columns),
            view,
            columns,
            starts,
            blocks,
            depths,
            near,
            owners,
        })
    }

    /// Columns across and down.
    pub fn columns(&self) -> UVec2 {
        self.columns
    }

    /// Bytes held by the grid.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<ViewGrid>()
            + std::mem::size_of_val(self.starts.as_slice())
            + std::mem::size_of_val(self.blocks.as_slice())
            + std::mem::size_of_val(self.depths.as_slice())
            + std::mem::size_of_val(self.near.as_slice())
            + std::mem::size_of_val(self.owners.as_slice())
    }

    /// The closest hit along `ray`: `Some(hit or none)` for a ray from the eye within the
    /// window, `None` for any other ray and for a ray that meets two triangles at exactly
    /// its nearest distance, which the grids answer instead.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Option<ViewHit>> {
        let column = self.column_of(ray)?;
        dispatch(
            X86Level::Avx512,
            ColumnIntersect {
                grid: self,
                ray,
                column,
            },
        )
    }

    /// The column of a ray from the eye within the window, and the ray's speed ahead.
    #[inline(always)]
    fn column_of(&self, ray: &Ray) -> Option<(usize, f32)> {
        if ray.origin != self.view.eye {
            return None;
        }
        let (p, w) = self.view.on_plane(ray.direction)?;
        // False for NaN too.
        if !(p.cmpge(self.view.lo).all() && p.cmple(self.view.hi).all()) {
            return None;
        }
        let c = column_at(p, self.view.lo, self.scale, self.columns);
        Some(((c.y * self.columns.x + c.x) as usize, w))
    }

    /// The nearest hit in column `column` (and the near list) of a ray whose speed ahead
    /// is `w`: `Some(hit or none)`, or `None` when two triangles are hit at the nearest
    /// distance.
    #[inline(always)]
    fn nearest_in_column(&self, ray: &Ray, (column, w): (usize, f32)) -> Option<Option<ViewHit>> {
        let mut best: Option<LaneHit> = None;
        let mut tied = false;
        // Hits below it count: before the ray's end, then up to and including the nearest
        // found, so that a second triangle at its distance is seen.
        let mut limit = ray.t_max;
        let mut test = |block: &Block, limit: &mut f32| {
            let Some((hit, tie)) = block.nearest_and_tie(ray, *limit) else {
                return;
            };
            match best {
                // The same triangle again is no tie: one in two columns may be met twice,
                // in a block they share.
                Some(b) if b.t == hit.t => tied |= tie || b.id != hit.id,
                _ => {
                    *limit = hit.t.next_up();
                    best = Some(hit);
                    tied = tie;
                }
            }
        };
        for block in &self.near {
            test(block, &mut limit);
        }
        let lanes = self.starts[column] as usize..self.starts[column + 1] as usize;
        // An empty column tests nothing (not the block its place falls in).
        let range = match lanes.is_empty() {
            true => 0..0,
            false => lanes.start / LANES..lanes.end.div_ceil(LANES),
        };
        for (block, &depth) in self.blocks[range.clone()].iter().zip(&self.depths[range]) {
            // Every later block's triangles lie at least this deep: past the hit found (a
            // triangle hit at its distance lies no deeper, so ties are seen).
            if depth > limit * w {
                break;
            }
            test(block, &mut limit);
        }
        if tied {
            return None;
        }
        Some(best.map(|hit| {
            let (source, triangle) = self.owners[hit.id as usize];
            ViewHit {
                t: hit.t,
                u: hit.u,
                v: hit.v,
                source,
                triangle,
            }
        }))
    }
}

/// Columns per unit of `view`'s plane. One formula for the build and the query, so that a
/// ray and the bounds of the triangles it meets map to columns alike ([`column_at`]).
fn scale_of(view: &View, columns: UVec2) -> Vec2 {
    columns.as_vec2() / (view.hi - view.lo)
}

/// The column holding plane point `p` (within the window, whose lower corner is `lo`).
/// Rising in `p`, so a point within bounds lies in a column within the bounds' columns.
#[inline(always)]
fn column_at(p: Vec2, lo: Vec2, scale: Vec2, columns: UVec2) -> UVec2 {
    ((p - lo) * scale).as_uvec2().min(columns - UVec2::ONE)
}

/// Where `triangle` goes in `view`'s grid.
fn place(view: &View, triangle: &Triangle) -> Place {
    let corners = triangle.vertices().map(|c| c - view.eye);
    let depths = corners.map(|c| c.dot(view.forward));
    let distance = corners
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0, f32::max);
    let nearest = depths.iter().copied().fold(f32::INFINITY, f32::min);
    let farthest = depths.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    if farthest < -NEAR_SHARE * distance {
        return Place::Nowhere;
    }
    if nearest < NEAR_SHARE * distance {
        return Place::Near;
    }
    let (mut lo, mut hi) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
    for c in corners {
        let Some((p, _)) = view.on_plane(c).filter(|(p, _)| p.is_finite()) else {
            return Place::Near;
        };
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let margin =
        PLANE_MARGIN * (1.0 + lo.abs().max(hi.abs()).max_element() + (hi - lo).max_element());
    let (lo, hi) = (lo - margin, hi + margin);
    if hi.cmplt(view.lo).any() || lo.cmpgt(view.hi).any() {
        return Place::Nowhere;
    }
    Place::Columns {
        lo: lo.max(view.lo),
        hi: hi.min(view.hi),
        depth: nearest - DEPTH_MARGIN * distance,
    }
}

/// Columns across and down for `triangles` projected into the window: about one per
/// triangle, at most as many as the view wants, about square in the plane.
fn column_counts(view: &View, triangles: usize) -> UVec2 {
    let wanted = triangles.clamp(1, view.max_columns.max(1) as usize) as f32;
    let size = view.hi - view.lo;
    let across = (wanted * size.x / size.y).sqrt().clamp(1.0, 16384.0);
    let down = (wanted / across).clamp(1.0, 16384.0);
    UVec2::new(across.round() as u32, down.round() as u32).max(UVec2::ONE)
}

/// The first and last column (inclusive) a placed triangle goes into.
fn column_range(view: &View, columns: UVec2, place: &Place) -> Option<[UVec2; 2]> {
    let Place::Columns { lo, hi, .. } = place else {
        return None;
    };
    let scale = scale_of(view, columns);
    Some([
        column_at(*lo, view.lo, scale, columns),
        column_at(*hi, view.lo, scale, columns),
    ])
}

/// Columns in an inclusive range.
fn cells([lo, hi]: &[UVec2; 2]) -> usize {
    ((hi.x - lo.x + 1) * (hi.y - lo.y + 1)) as usize
}

/// `triangles` (with their lane ids) in blocks of eight, in order.
fn fill_blocks<'a>(triangles: impl Iterator<Item = (&'a Triangle, u32)>) -> Vec<Block> {
    let mut blocks = Vec::new();
    for (k, (triangle, id)) in triangles.enumerate() {
        if k % LANES == 0 {
            blocks.push(Block::EMPTY);
        }
        blocks
            .last_mut()
            .expect("pushed")
            .set(k % LANES, triangle, id);
    }
    blocks
}

/// The columns' blocks: each column's triangles by least depth (then index, so the grid is
/// the same on any thread count), the columns one after another in lanes of blocks of
/// eight with no lane left empty, and each block's least depth. A block may hold the end
/// of one column and the start of the next: a ray then also tests the other column's
/// triangles there, which can only find real hits no nearer than the nearest, and every
/// later triangle of its own column still lies at least as deep as the block's least depth.
/// Returns the first lane of each column (and the end), the blocks and their depths.
fn fill_columns(
    triangles: &[(Triangle, (u32, u32))],
    places: &[Place],
    ranges: &[Option<[UVec2; 2]>],
    columns: UVec2,
) -> (Vec<u32>, Vec<Block>, Vec<f32>) {
    let count = (columns.x * columns.y) as usize;
    let column_ids = |[lo, hi]: [UVec2; 2]| {
        (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| (y * columns.x + x) as usize))
    };
    let mut starts = vec![0usize; count + 1];
    for range in ranges.iter().flatten() {
        for c in column_ids(*range) {
            starts[c + 1] += 1;
        }
    }
    for c in 0..count {
        starts[c + 1] += starts[c];
    }
    let mut references = vec![(0.0f32, 0u32); starts[count]];
    let mut next = starts.clone();
    for (i, range) in ranges.iter().enumerate() {
        let (Some(range), Place::Columns { depth, .. }) = (range, &places[i]) else {
            continue;
        };
        for c in column_ids(*range) {
            references[next[c]] = (*depth, i as u32);
            next[c] += 1;
        }
    }
    let mut parts = Vec::with_capacity(count);
    let mut rest = references.as_mut_slice();
    for c in 0..count {
        let (column, after) = std::mem::take(&mut rest).split_at_mut(starts[c + 1] - starts[c]);
        parts.push(column);
        rest = after;
    }
    parts.into_par_iter().for_each(|column| {
        column.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    });
    let total = references.len().div_ceil(LANES);
    // A ray's column lies anywhere in the blocks: 2 MiB pages spare it a TLB miss, as for
    // the grids' blocks.
    let mut blocks = crate::accel::huge_pages::vec_with_capacity(total);
    blocks.resize(total, Block::EMPTY);
    let mut depths = vec![0.0f32; total];
    (blocks.par_iter_mut().zip(&mut depths))
        .zip(references.par_chunks(LANES))
        .for_each(|((block, depth), chunk)| {
            *depth = chunk.iter().map(|r| r.0).fold(f32::INFINITY, f32::min);
            for (lane, &(_, i)) in chunk.iter().enumerate() {
                block.set(lane, &triangles[i as usize].0, i);
            }
        });
    let starts = starts.iter().map(|&s| s as u32).collect();
    (starts, blocks, depths)
}

/// The column query as a [`Kernel`]: the blocks' eight lanes are one vector with AVX2 and
/// AVX-512, as in the grid's own queries (the same operations, so the same answers).
struct ColumnIntersect<'a> {
    grid: &'a ViewGrid,
    ray: &'a Ray,
    column: (usize, f32),
}

impl Kernel for ColumnIntersect<'_> {
    type Output = Option<Option<ViewHit>>;
    #[inline(always)]
    fn run<const FUSED: bool>(self) -> Option<Option<ViewHit>> {
        self.grid.nearest_in_column(self.ray, self.column)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;

    fn random_vec(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0
    }

    /// The nearest hit along `ray` by testing every triangle in turn (the first of equals),
    /// and whether another triangle is hit at the same distance.
    fn nearest_of_every(triangles: &[Triangle], ray: &Ray) -> (Option<(f32, f32, f32, u32)>, bool) {
        let mut best: Option<(f32, f32, f32, u32)> = None;
        for (i, t) in triangles.iter().enumerate() {
            if let Some(hit) = t.intersect(ray, best.map_or(ray.t_max, |b| b.0)) {
                best = Some((hit.t, hit.u, hit.v, i as u32));
            }
        }
        let tie = best.is_some_and(|b| {
            triangles.iter().enumerate().any(|(i, t)| {
                i as u32 != b.3 && t.intersect(ray, f32::INFINITY).is_some_and(|h| h.t == b.0)
            })
        });
        (best, tie)
    }

    /// A mesh about an eye at the origin: small triangles ahead, some sharing edges, some
    /// doubled, large ones that pass beside and behind the eye, some wholly behind it.
    fn mesh_about_the_eye(rng: &mut Rng, count: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        for k in 0..count {
            let n = vertices.len() as u32;
            match k % 23 {
                // Large, around the eye.
                0 => (0..3).for_each(|_| vertices.push(random_vec(rng) * 6.0)),
                // The last triangle again (a doubled face, as downloaded models have): every
                // ray through it meets two triangles at one distance.
                3 if n >= 3 => {
                    indices.push(*indices.last().expect("a triangle before"));
                    continue;
                }
                // Sharing an edge with the last triangle.
                1 | 2 if n >= 3 => {
                    let last = vertices[n as usize - 1];
                    vertices.push(last + random_vec(rng) * 0.3);
                    indices.push([n - 2, n - 1, n]);
                    continue;
                }
                _ => {
                    let at = random_vec(rng) * 3.0;
                    (0..3).for_each(|_| vertices.push(at + random_vec(rng) * 0.3));
                }
            }
            indices.push([n, n + 1, n + 2]);
        }
        (vertices, indices)
    }

    /// Rays from the eye through the window find what testing every triangle finds, and what
    /// the grid finds: the same triangle, `t`, `u` and `v` bit for bit; a ray that meets two
    /// triangles at exactly its nearest distance, and only such a ray, is left to the grid.
    /// Rays through triangles' edges and corners are among them.
    #[test]
    fn a_ray_from_the_eye_finds_what_testing_every_triangle_finds() {
        let mut rng = Rng::new(61, 2);
        let (mut hits, mut misses, mut answered, mut edge_hits) = (0, 0, 0, 0);
        let mut declined_ties = 0;
        for scene in 0..40 {
            let (vertices, indices) = mesh_about_the_eye(&mut rng, 30 + 10 * scene);
            let triangles: Vec<Triangle> = (indices.iter())
                .map(|&[a, b, c]| {
                    Triangle::new(
                        vertices[a as usize],
                        vertices[b as usize],
                        vertices[c as usize],
                    )
                })
                .collect();
            let doubled: Vec<usize> = (1..indices.len())
                .filter(|&i| indices[i] == indices[i - 1])
                .collect();
            let grid = Grid::from_mesh(vertices.clone(), &indices);
            let forward = random_vec(&mut rng).normalize();
            let right = forward.any_orthonormal_vector();
            let view = View {
                eye: Vec3::ZERO,
                right,
                up: forward.cross(right),
                forward,
                lo: Vec2::new(-0.8, -0.5),
                hi: Vec2::new(0.7, 0.6),
                max_columns: 20 + 37 * scene as u32,
            };
            let view_grid = ViewGrid::build(&[&grid], view).expect("few triangles near the eye");
            for k in 0..400 {
                let direction = if k % 4 == 0 {
                    // Through a point of a triangle's edge.
                    let t = &triangles[k / 4 % triangles.len()];
                    let a = rng.uniform();
                    [
                        t.v0 + a * t.e1,
                        t.v0 + a * t.e2,
                        t.v0 + t.e1 + a * (t.e2 - t.e1),
                    ][k / 4 % 3]
                } else if k % 8 == 2 {
                    // Through a point inside a doubled triangle.
                    let t = &triangles[doubled[k / 8 % doubled.len()]];
                    let (a, b) = (rng.uniform(), rng.uniform());
                    t.v0 + 0.5 * a * t.e1 + 0.5 * b * t.e2
                } else {
                    let p = view.lo + (view.hi - view.lo) * Vec2::new(rng.uniform(), rng.uniform());
                    (forward + p.x * view.right + p.y * view.up) * (0.5 + 2.0 * rng.uniform())
                };
                let ray = Ray {
                    t_min: if k % 3 == 0 { 0.05 } else { 0.0 },
                    ..Ray::new(Vec3::ZERO, direction)
                };
                let (expected, tie) = nearest_of_every(&triangles, &ray);
                let inside = view.on_plane(direction).is_some_and(|(p, _)| {
                    p.cmpgt(view.lo + 1e-3).all() && p.cmplt(view.hi - 1e-3).all()
                });
                let Some(got) = view_grid.intersect(&ray) else {
                    assert!(
                        !inside || tie,
                        "scene {scene} ray {k}: a ray within the window and without a tie is not answered"
                    );
                    declined_ties += usize::from(inside);
                    continue;
                };
                assert!(!tie, "scene {scene} ray {k}: a tie answered");
                answered += 1;
                let got = got.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.triangle));
                let want = expected.map(|e| (e.0.to_bits(), e.1.to_bits(), e.2.to_bits(), e.3));
                assert_eq!(got, want, "scene {scene} ray {k}: {ray:?}");
                let by_grid = grid.intersect(&ray);
                let by_grid =
                    by_grid.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.triangle));
                assert_eq!(got, by_grid, "scene {scene} ray {k}: the grid's own answer");
                hits += usize::from(want.is_some());
                misses += usize::from(want.is_none());
                edge_hits += usize::from(want.is_some() && k % 4 == 0);
            }
            let elsewhere = Ray::new(Vec3::splat(1e-3), forward);
            assert_eq!(
                view_grid.intersect(&elsewhere),
                None,
                "a ray not from the eye"
            );
        }
        assert!(
            answered > 10_000 && hits > 3_000 && misses > 2_000 && edge_hits > 300,
            "{answered} answered, {hits} hits, {misses} misses, {edge_hits} on edges"
        );
        assert!(declined_ties > 25, "{declined_ties} ties left to the grid");
    }

    /// The grid is the same built on one thread as on several.
    #[test]
    fn the_view_grid_is_the_same_on_any_thread_count() {
        let mut rng = Rng::new(7, 9);
        let (vertices, indices) = mesh_about_the_eye(&mut rng, 2_000);
        let grid = Grid::from_mesh(vertices, &indices);
        let view = View {
            eye: Vec3::ZERO,
            right: Vec3::X,
            up: Vec3::Y,
            forward: Vec3::NEG_Z,
            lo: Vec2::splat(-1.0),
            hi: Vec2::splat(1.0),
            max_columns: 1_000,
        };
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let alone = one.install(|| ViewGrid::build(&[&grid], view));
        let blocks = alone.as_ref().map(|g| (g.blocks.len(), g.near.len()));
        assert!(blocks.is_some_and(|(b, _)| b > 100), "{blocks:?}");
        assert_eq!(alone, ViewGrid::build(&[&grid], view));
    }
}
