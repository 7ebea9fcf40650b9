//! Ray traversal: the 3D-DDA of Amanatides & Woo (1987), "A fast voxel traversal algorithm
//! for ray tracing", over the two-level cell index ([`crate::accel::grid::storage::cells`]): an empty macrocell
//! sends the walk past the whole empty box ahead of it in one step ([`crate::accel::grid::storage::reach`]), an
//! empty cell past the empty cube ahead of it (or of its 2³ unit of cells) if that is two
//! or more cells a side ([`crate::accel::grid::storage::cell_reach`]), any other empty cell costs a bit test and
//! a step, and an
//! occupied cell's blocks are tested eight triangles at a time. A grid of one cell is not
//! walked: its blocks are tested at once.

use glam::UVec3;

pub(in crate::accel::grid) mod occupied;
pub(crate) mod prefetch;
pub(in crate::accel::grid) mod stats;

use stats::TraversalStats;

use super::{Grid, GridHit};
use crate::accel::Ray;
use crate::accel::isa::{Kernel, X86Level, dispatch};

impl Grid {
    /// The closest hit along `ray`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<GridHit> {
        self.ask(Intersect { ray, stats: () })
    }

    /// [`Grid::intersect`], reporting its work to `stats`.
    pub fn intersect_counting(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        self.ask(Intersect {
            ray,
            stats: stats.lend(),
        })
    }

    /// Runs `query` in the walk compiled for this grid: reaches per cell or per 2³ unit of
    /// cells ([`crate::accel::grid::storage::cell_reach`]), with or without cell boxes,
    /// each compiled in functions of its own so that no grid pays for another's code (in
    /// one function, the 11k dragon's queries took 1.01–1.03 the time), and each for the
    /// widest instruction set the processor has ([`dispatch`]).
    #[inline(always)]
    fn ask<Q: Query>(&self, query: Q) -> Q::Output {
        match (self.cells.unit_shift(), self.cells.box_margin().is_some()) {
            (0, false) => dispatch(X86Level::Avx512, Asked::<Q, 0, false> { grid: self, query }),
            (0, true) => dispatch(X86Level::Avx512, Asked::<Q, 0, true> { grid: self, query }),
            (_, false) => dispatch(X86Level::Avx512, Asked::<Q, 1, false> { grid: self, query }),
            (_, true) => dispatch(X86Level::Avx512, Asked::<Q, 1, true> { grid: self, query }),
        }
    }

    #[inline(always)]
    fn intersect_portable<const FUSED: bool, const UNIT: u32, const BOXED: bool>(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        // The nearest hit found so far, wherever it lies; it is the answer once it lies
        // within the cell being visited, since every later cell lies beyond that cell.
        let mut nearest: Option<GridHit> = None;
        let mut t_nearest = ray.t_max;
        let mut cells = self.occupied_cells::<true, FUSED, UNIT, BOXED>(ray);
        while let Some((range, mask, limit)) = cells.next(stats) {
            for block in self.cell_blocks::<BOXED>(&range, mask) {
                stats.test_triangles(block.len());
                if let Some(hit) = block.nearest(ray, t_nearest) {
                    t_nearest = hit.t;
                    nearest = Some(hit.into());
                }
            }
            if t_nearest <= limit {
                break;
            }
        }
        nearest
    }

    /// True for a grid of one occupied cell without block boxes (a wall, a lamp, a cube: a
    /// mesh of a few triangles), which [`Grid::intersect_one_cell`] and
    /// [`Grid::occluded_one_cell`] answer without a walk.
    pub(crate) fn is_one_cell(&self) -> bool {
        self.frame.resolution == UVec3::ONE
            && !self.blocks.is_empty()
            && self.block_boxes.is_empty()
    }

    /// [`Grid::intersect_counting`] for a grid of one cell ([`Grid::is_one_cell`]): the
    /// same blocks tested in the same order, so the same hit, but inlined into the caller
    /// (the top level, already compiled for the processor's instruction set) rather than
    /// dispatched: for a scene of walls and lamps the dispatch and the walk's setup cost
    /// more than the triangles.
    #[inline(always)]
    pub(crate) fn intersect_one_cell(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        stats.visit_occupied();
        let mut nearest: Option<GridHit> = None;
        let mut t_nearest = ray.t_max;
        for block in &self.blocks {
            stats.test_triangles(block.len());
            if let Some(hit) = block.nearest(ray, t_nearest) {
                t_nearest = hit.t;
                nearest = Some(hit.into());
            }
        }
        nearest
    }

    /// [`Grid::occluded_counting`] for a grid of one cell ([`Grid::is_one_cell`]), inlined
    /// as [`Grid::intersect_one_cell`] is.
    #[inline(always)]
    pub(crate) fn occluded_one_cell(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        stats.visit_occupied();
        // A loop rather than `Iterator::any`, whose closure was compiled out of line, for
        // the baseline instruction set.
        for block in &self.blocks {
            stats.test_triangles(block.len());
            if block.any(ray, ray.t_max) {
                return true;
            }
        }
        false
    }

    /// Walks `ray` through the grid as [`Grid::intersect`] does when the nearest hit lies
    /// at `t_stop` (∞ for none) — the same steps, the look-ahead to the next occupied cell
    /// included — without reading or testing any triangle; returns the number of occupied
    /// cells given out. For the benchmark, to split a query's time between the walk and the
    /// triangles.
    pub fn walk(&self, ray: &Ray, t_stop: f32) -> usize {
        self.ask(Walk { ray, t_stop })
    }

    #[inline(always)]
    fn walk_portable<const FUSED: bool, const UNIT: u32, const BOXED: bool>(
        &self,
        ray: &Ray,
        t_stop: f32,
    ) -> usize {
        let mut cells = self.occupied_cells::<false, FUSED, UNIT, BOXED>(ray);
        let mut visited = 0;
        while let Some((.., limit)) = cells.next(&mut ()) {
            visited += 1;
            if t_stop <= limit {
                break;
            }
        }
        visited
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`): for shadow rays.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.ask(Occluded { ray, stats: () })
    }

    /// [`Grid::occluded`], reporting its work to `stats`.
    pub fn occluded_counting(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        self.ask(Occluded {
            ray,
            stats: stats.lend(),
        })
    }

    /// The cells are walked from the segment's far end back to its origin (the answer does
    /// not depend on their order, and each triangle is still tested against `ray` itself,
    /// so it is the one a forward walk gives). A shadow segment starts on the surface it
    /// leaves, whose cells are crowded with triangles that seldom block it, and ends on a
    /// light or beyond the box: walked from that end, a blocked segment stops at the
    /// blocker nearest the end without testing them. Against the forward walk, identical
    /// answers (`tools/dev/grid-ab.sh`, 50,000 segments each): light segments 0.61–0.64 the
    /// time on the full dragon, 0.73 on the 203k, 0.95 on the 11k; the bounce rays cut to
    /// random lengths 0.81, 0.88 and 1.01; light segments from a camera's hits, each traced
    /// after its camera ray (set `seen`), 0.94 on the full dragon and 1.00 on the 11k.
    #[inline(always)]
    fn occluded_portable<const FUSED: bool, const UNIT: u32, const BOXED: bool>(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> bool {
        let walked = match self.frame.resolution {
            UVec3::ONE => *ray,
            _ => self.frame.reversed(ray).unwrap_or(*ray),
        };
        let mut cells = self.occupied_cells::<true, FUSED, UNIT, BOXED>(&walked);
        while let Some((range, mask, _)) = cells.next(stats) {
            for block in self.cell_blocks::<BOXED>(&range, mask) {
                stats.test_triangles(block.len());
                if block.any(ray, ray.t_max) {
                    return true;
                }
            }
        }
        false
    }
}

/// A query of the grid, written once for every form of grid and instruction set.
trait Query {
    /// What it answers.
    type Output;
    /// Asks it of `grid`, whose reaches are per unit of 2^`UNIT` cells and which keeps
    /// cell boxes if `BOXED`, with fused multiply-adds if `FUSED`.
    fn run<const FUSED: bool, const UNIT: u32, const BOXED: bool>(
        self,
        grid: &Grid,
    ) -> Self::Output;
}

/// A query of one form of grid, as a [`Kernel`] for [`dispatch`].
struct Asked<'a, Q, const UNIT: u32, const BOXED: bool> {
    grid: &'a Grid,
    query: Q,
}

impl<Q: Query, const UNIT: u32, const BOXED: bool> Kernel for Asked<'_, Q, UNIT, BOXED> {
    type Output = Q::Output;
    #[inline(always)]
    fn run<const FUSED: bool>(self) -> Q::Output {
        self.query.run::<FUSED, UNIT, BOXED>(self.grid)
    }
}

/// The closest-hit query, with its counter by value (the unit type: no word at all), so
/// that with the grid it is handed in two registers.
struct Intersect<'a, S> {
    ray: &'a Ray,
    stats: S,
}

impl<S: TraversalStats> Query for Intersect<'_, S> {
    type Output = Option<GridHit>;
    #[inline(always)]
    fn run<const FUSED: bool, const UNIT: u32, const BOXED: bool>(
        mut self,
        grid: &Grid,
    ) -> Option<GridHit> {
        grid.intersect_portable::<FUSED, UNIT, BOXED>(self.ray, &mut self.stats)
    }
}

/// The shadow query, its counter by value as [`Intersect`]'s.
struct Occluded<'a, S> {
    ray: &'a Ray,
    stats: S,
}

impl<S: TraversalStats> Query for Occluded<'_, S> {
    type Output = bool;
    #[inline(always)]
    fn run<const FUSED: bool, const UNIT: u32, const BOXED: bool>(mut self, grid: &Grid) -> bool {
        grid.occluded_portable::<FUSED, UNIT, BOXED>(self.ray, &mut self.stats)
    }
}

/// The walk alone ([`Grid::walk`]).
struct Walk<'a> {
    ray: &'a Ray,
    t_stop: f32,
}

impl Query for Walk<'_> {
    type Output = usize;
    #[inline(always)]
    fn run<const FUSED: bool, const UNIT: u32, const BOXED: bool>(self, grid: &Grid) -> usize {
        grid.walk_portable::<FUSED, UNIT, BOXED>(self.ray, self.t_stop)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::stats::TraversalCounts;
    use super::*;
    use crate::accel::Triangle;
    use crate::accel::grid::storage::cell_box::{self, MASKED_BLOCKS};

    /// Asserts that `grid` answers the shadow query of ray `k` as `expected` does, in its
    /// fast walk and in its portable one (reaches per 2^`UNIT` cells, boxes if `BOXED`).
    fn assert_same_occlusion<const UNIT: u32, const BOXED: bool>(
        expected: &Grid,
        grid: &Grid,
        ray: &Ray,
        k: usize,
    ) {
        let blocked = expected.occluded(ray);
        assert_eq!(grid.occluded(ray), blocked, "ray {k}");
        let portable = grid.occluded_portable::<false, UNIT, BOXED>(ray, &mut ());
        assert_eq!(portable, blocked, "ray {k}");
    }

    /// The nearest hit along `ray` (parameter and index) found by testing every triangle in
    /// turn: what a grid's query must find.
    fn nearest_of_every(triangles: &[Triangle], ray: &Ray) -> Option<(f32, usize)> {
        triangles.iter().enumerate().fold(None, |best, (i, t)| {
            match t.intersect(ray, best.map_or(ray.t_max, |b: (f32, usize)| b.0)) {
                Some(hit) => Some((hit.t, i)),
                None => best,
            }
        })
    }

    /// A sphere of radius 1 at the origin, `n` × 2`n` quads split in two.
    fn sphere(n: usize) -> Vec<Triangle> {
        let at = |i: usize, j: usize| {
            let (theta, phi) = (
                std::f32::consts::PI * i as f32 / n as f32,
                std::f32::consts::TAU * j as f32 / (2 * n) as f32,
            );
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            )
        };
        (0..n)
            .flat_map(|i| (0..2 * n).map(move |j| (i, j)))
            .flat_map(|(i, j)| {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                [Triangle::new(a, b, c), Triangle::new(a, c, d)]
            })
            .collect()
    }

    /// A grid of one cell answers in the top level's inlined form what its query and every
    /// triangle tested in turn answer: meshes of a few random triangles (a wall, a lamp, a
    /// box), rays from inside and outside, shadow segments ending before, at and past the
    /// nearest hit.
    #[test]
    fn a_grid_of_one_cell_answers_inline_what_its_query_answers() {
        let mut rng = crate::render::sampling::Rng::new(43, 5);
        let (mut one_cell, mut hits) = (0, 0);
        for mesh in 0..200 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let triangles: Vec<Triangle> = (0..1 + mesh % 12)
                .map(|_| {
                    let a = Vec3::new(u(), u(), u());
                    Triangle::new(
                        a,
                        a + Vec3::new(u(), u(), u()),
                        a + Vec3::new(u(), u(), u()),
                    )
                })
                .collect();
            let grid = Grid::build(triangles.clone());
            if !grid.is_one_cell() {
                continue;
            }
            one_cell += 1;
            for k in 0..100 {
                let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 1.0 } else { 4.0 };
                let mut ray = Ray::new(origin, (Vec3::new(u(), u(), u()) - origin).normalize());
                let nearest = nearest_of_every(&triangles, &ray);
                let inline = grid.intersect_one_cell(&ray, &mut ());
                assert_eq!(inline, grid.intersect(&ray), "mesh {mesh}, ray {k}");
                assert_eq!(inline.map(|h| (h.t, h.triangle as usize)), nearest);
                hits += usize::from(nearest.is_some());
                for end in [0.999, 1.0, 1.001] {
                    ray.t_max = nearest.map_or(8.0, |n| n.0 * end);
                    let blocked = grid.occluded_one_cell(&ray, &mut ());
                    assert_eq!(blocked, grid.occluded(&ray), "mesh {mesh}, ray {k}");
                    assert_eq!(
                        blocked,
                        nearest.is_some() && end > 1.0,
                        "mesh {mesh}, ray {k}"
                    );
                }
            }
        }
        assert!(
            one_cell > 50 && hits > 2_000,
            "{one_cell} meshes, {hits} hits"
        );
    }

    /// Every kind of step is counted where the walk takes it: a step of the cell count is
    /// either an entry into an occupied macrocell, a leap over empty macrocells, or a move
    /// within a macrocell by a leap over empty cells or a plain step.
    #[test]
    fn the_walk_counts_each_kind_of_step() {
        let grid = Grid::build(sphere(60));
        let mut total = TraversalCounts::default();
        for k in 0..400 {
            let a = k as f32 * 0.7;
            let origin = Vec3::new(3.0 * a.cos(), 0.01 * k as f32 - 2.0, 3.0 * a.sin());
            // Half aimed at the sphere, half passing beside it.
            let target = Vec3::new(0.0, 0.0, if k % 2 == 0 { 0.0 } else { 1.3 });
            let ray = Ray::new(origin, (target - origin).normalize());
            let mut counts = TraversalCounts::default();
            grid.intersect_counting(&ray, &mut counts);
            let outer = counts.macrocell_entries + counts.macrocell_leaps;
            assert!(counts.cells >= outer, "ray {k}: {counts:?}");
            assert!(
                counts.cells <= outer + counts.cell_leaps + counts.plain_steps,
                "ray {k}: {counts:?}"
            );
            total.macrocell_entries += counts.macrocell_entries;
            total.macrocell_leaps += counts.macrocell_leaps;
            total.cell_leaps += counts.cell_leaps;
            total.plain_steps += counts.plain_steps;
        }
        assert!(
            total.macrocell_entries > 0 && total.macrocell_leaps > 0,
            "{total:?}"
        );
        assert!(total.cell_leaps > 0 && total.plain_steps > 0, "{total:?}");
    }

    /// A ray from outside the grid's box, whose walk ahead stops at each new occupied
    /// macrocell and goes on from there when the tested cell holds no hit, finds the
    /// nearest hit that testing every triangle finds, and so does a shadow ray.
    #[test]
    fn a_walk_that_pauses_ahead_finds_the_nearest_hit() {
        let triangles = sphere(120);
        let grid = Grid::build(triangles.clone());
        let mut rng = crate::render::sampling::Rng::new(37, 3);
        let (mut counts, mut hits) = (TraversalCounts::default(), 0);
        for k in 0..3_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()).normalize() * 3.0;
            // Aimed near the sphere's rim, so many rays pass occupied cells before a hit.
            let target = Vec3::new(u(), u(), u()) * 1.05;
            let mut ray = Ray::new(origin, (target - origin).normalize());
            let nearest = nearest_of_every(&triangles, &ray);
            let found = grid.intersect_counting(&ray, &mut counts);
            assert_eq!(
                found.map(|h| (h.t, h.triangle as usize)),
                nearest,
                "ray {k}: {ray:?}"
            );
            hits += usize::from(nearest.is_some());
            ray.t_max = nearest.map_or(4.0, |n| n.0 * 0.999);
            assert!(!grid.occluded(&ray), "ray {k}: {ray:?}");
            ray.t_max = nearest.map_or(4.0, |n| n.0 * 1.001);
            assert_eq!(grid.occluded(&ray), nearest.is_some(), "ray {k}: {ray:?}");
        }
        assert!(
            hits > 1_000 && counts.pauses > 500,
            "{hits} hits, {counts:?}"
        );
    }

    /// A shadow query, whose cells are walked from the segment's far end, finds what testing
    /// every triangle finds: for segments ending exactly at their nearest hit, one ulp past
    /// it and anywhere, segments to infinity, rays from inside and outside the box, rays
    /// starting just before a triangle (the walk's last cell decides), and rays along an
    /// axis in the planes of cell faces (where a walk from either end meets cell boundaries
    /// at every step).
    #[test]
    fn a_shadow_query_walked_from_the_far_end_finds_what_testing_every_triangle_finds() {
        let triangles = sphere(50);
        let grid = Grid::build(triangles.clone());
        let frame = grid.frame;
        let mut rng = crate::render::sampling::Rng::new(41, 4);
        let (mut blocked, mut rays) = (0, 0);
        for k in 0..4_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let (origin, direction) = if k % 4 == 3 {
                // On cell faces of two axes, along the third.
                let axis = k / 4 % 3;
                let face = |a: usize, x: f32| {
                    let cells = (x * 0.5 + 0.5) * frame.resolution[a] as f32;
                    frame.bounds.min[a] + cells.round() * frame.cell_size[a]
                };
                let mut o = Vec3::new(face(0, u()), face(1, u()), face(2, u()));
                o[axis] = if k % 8 < 4 { -2.0 } else { 0.3 * u() };
                let mut d = Vec3::ZERO;
                d[axis] = if k % 3 == 0 { -1.0 } else { 1.0 };
                (o, d)
            } else if k % 4 == 2 {
                // Just before a point of a triangle, as a shadow ray leaving a surface is:
                // the blocker lies at the end where the walk from the far end stops.
                let t = &triangles[((u() * 0.5 + 0.5) * triangles.len() as f32) as usize];
                let d = Vec3::new(u(), u(), u()).normalize();
                let (a, b, back) = (u() * 0.25 + 0.25, u() * 0.25 + 0.25, u() * 5e-5 + 5e-5);
                (t.v0 + a * t.e1 + b * t.e2 - d * back, d)
            } else {
                let o = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 2.5 } else { 0.9 };
                (o, Vec3::new(u(), u(), u()).normalize())
            };
            let ray = Ray::new(origin, direction);
            let nearest = triangles
                .iter()
                .filter_map(|t| t.intersect(&ray, f32::INFINITY))
                .map(|h| h.t)
                .reduce(f32::min);
            let ends = [
                nearest.unwrap_or(1.0),
                nearest.map_or(2.0, |t| t.next_up()),
                4.0 * rng.uniform(),
                f32::INFINITY,
            ];
            for t_max in ends {
                let segment = ray.with_t_max(t_max);
                let expected = triangles
                    .iter()
                    .any(|t| t.intersect(&segment, t_max).is_some());
                assert_eq!(grid.occluded(&segment), expected, "ray {k}: {segment:?}");
                blocked += usize::from(expected);
                rays += 1;
            }
        }
        assert!(
            blocked > rays / 4 && blocked < rays * 3 / 4,
            "{blocked} of {rays}"
        );
    }

    /// The portable query (compiled for baseline x86-64 here) finds what the queries
    /// compiled for this processor find (AVX-512 and AVX2, where it has them): the same
    /// nearest hit for every ray, and the same shadow answers.
    #[test]
    fn the_portable_walk_finds_what_the_fast_one_finds() {
        let grid = Grid::build(sphere(90));
        let mut rng = crate::render::sampling::Rng::new(29, 1);
        let mut hits = 0;
        for k in 0..20_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 3.0 } else { 0.9 };
            let direction = Vec3::new(u(), u(), u()).normalize();
            let mut ray = Ray::new(origin, direction);
            let fast = grid.intersect(&ray);
            let portable = grid.intersect_portable::<false, 0, false>(&ray, &mut ());
            assert_eq!(fast, portable, "ray {k}: {ray:?}");
            // On a processor with AVX-512, the AVX2 version too.
            let query = Asked::<_, 0, false> {
                grid: &grid,
                query: Intersect {
                    ray: &ray,
                    stats: &mut (),
                },
            };
            assert_eq!(
                dispatch(X86Level::Avx2, query),
                portable,
                "ray {k}: {ray:?}"
            );
            hits += usize::from(fast.is_some());
            ray.t_max = 1.5;
            let blocked = grid.occluded_portable::<false, 0, false>(&ray, &mut ());
            assert_eq!(grid.occluded(&ray), blocked, "ray {k}: {ray:?}");
            let query = Asked::<_, 0, false> {
                grid: &grid,
                query: Occluded {
                    ray: &ray,
                    stats: &mut (),
                },
            };
            assert_eq!(dispatch(X86Level::Avx2, query), blocked, "ray {k}: {ray:?}");
        }
        assert!(hits > 5_000, "{hits} hits");
    }

    /// A grid whose reaches are kept per 2³ unit of cells (as a grid whose blocks outgrow
    /// the caches keeps them, [`crate::accel::grid::storage::cell_reach::unit_shift_for`]) is valid and
    /// finds, by other steps, exactly what the same grid with reaches per cell finds, for
    /// rays from outside and from among the cells, and the same shadow answers.
    #[test]
    fn reaches_per_unit_of_cells_find_what_reaches_per_cell_find() {
        let per_cell = Grid::build(sphere(90));
        assert_eq!(per_cell.cells.unit_shift(), 0);
        let mut per_unit = per_cell.clone();
        per_unit.cells.fill_reaches(1);
        assert_eq!(per_unit.cells.unit_shift(), 1);
        per_unit.validate().unwrap();
        assert!(per_unit.stats().bytes < per_cell.stats().bytes);
        let mut rng = crate::render::sampling::Rng::new(37, 3);
        let (mut hits, mut leaps) = (0, [0, 0]);
        for k in 0..20_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 3.0 } else { 0.9 };
            let mut ray = Ray::new(origin, Vec3::new(u(), u(), u()).normalize());
            let mut counts = [TraversalCounts::default(); 2];
            let hit = per_cell.intersect_counting(&ray, &mut counts[0]);
            assert_eq!(
                per_unit.intersect_counting(&ray, &mut counts[1]),
                hit,
                "ray {k}"
            );
            // The portable walk of units too (the query above ran the fast one).
            let portable = per_unit.intersect_portable::<false, 1, false>(&ray, &mut ());
            assert_eq!(portable, hit, "ray {k}");
            hits += usize::from(hit.is_some());
            for (leaps, counts) in leaps.iter_mut().zip(counts) {
                *leaps += counts.cell_leaps;
            }
            ray.t_max = 1.5;
            assert_same_occlusion::<1, false>(&per_cell, &per_unit, &ray, k);
        }
        assert!(hits > 5_000, "{hits} hits");
        // Both walks leave cubes of cells.
        assert!(leaps.iter().all(|&n| n > 1_000), "{leaps:?}");
    }

    /// A grid that keeps a box per occupied cell (as a grid whose blocks outgrow the caches
    /// does, [`crate::accel::grid::storage::cell_box::boxes_for`]) is valid, passes cells by their boxes,
    /// and finds exactly what the same grid without boxes finds, in both walks, with
    /// reaches per cell and per 2³ unit, for rays from outside and from among the cells,
    /// rays of huge and tiny direction vectors, and shadow segments; and a box that does
    /// not hold its cell's triangles fails validation.
    #[test]
    fn cell_boxes_pass_cells_and_change_no_answer() {
        let plain = Grid::build(sphere(90));
        assert!(plain.cells.box_margin().is_none());
        let margin = cell_box::margin_for(&plain.frame).unwrap();
        let mut rng = crate::render::sampling::Rng::new(43, 5);
        for unit in [0, 1] {
            let mut unboxed = plain.clone();
            unboxed.cells.fill_reaches(unit);
            let mut boxed = unboxed.clone();
            boxed.cells.set_cell_boxes(boxed.cell_boxes(), margin);
            boxed.validate().unwrap();
            let (mut hits, mut tests) = (0, [0, 0]);
            for k in 0..20_000 {
                let mut u = || rng.uniform() * 2.0 - 1.0;
                let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 3.0 } else { 0.9 };
                let scale = [1.0, 1e-30, 1e12][k % 3];
                let mut ray = Ray::new(origin, Vec3::new(u(), u(), u()).normalize() * scale);
                let mut counts = [TraversalCounts::default(); 2];
                let hit = unboxed.intersect_counting(&ray, &mut counts[0]);
                assert_eq!(
                    boxed.intersect_counting(&ray, &mut counts[1]),
                    hit,
                    "ray {k}"
                );
                let portable = match unit {
                    0 => boxed.intersect_portable::<false, 0, true>(&ray, &mut ()),
                    _ => boxed.intersect_portable::<false, 1, true>(&ray, &mut ()),
                };
                assert_eq!(portable, hit, "ray {k}");
                hits += usize::from(hit.is_some());
                for (tests, counts) in tests.iter_mut().zip(counts) {
                    *tests += counts.tests;
                }
                ray.t_max = 1.5 / scale;
                match unit {
                    0 => assert_same_occlusion::<0, true>(&unboxed, &boxed, &ray, k),
                    _ => assert_same_occlusion::<1, true>(&unboxed, &boxed, &ray, k),
                }
            }
            assert!(hits > 5_000, "{hits} hits");
            // The boxes spare a good share of the triangle tests.
            assert!(tests[1] * 10 < tests[0] * 9, "tests {tests:?}");
        }
        // A box shrunk to a corner of its cell no longer holds its triangles.
        let mut broken = plain.clone();
        let mut boxes = broken.cell_boxes();
        let middle = boxes.len() / 2;
        boxes[middle] = cell_box::encode(Vec3::ZERO, Vec3::splat(0.01));
        broken.cells.set_cell_boxes(boxes, margin);
        let error = broken.validate().unwrap_err();
        assert!(error.contains("box does not hold"), "{error}");
    }

    /// A grid that keeps boxes per block tests only the blocks of a cell whose boxes the ray
    /// meets, and finds what the same grid without boxes finds (the same hit parameter, and
    /// the same triangle but where two are hit at the same distance, which the order of a
    /// cell's triangles decides), fewer triangles tested than with boxes per cell alone.
    #[test]
    fn block_boxes_pass_blocks_and_change_no_answer() {
        let triangles = sphere(90);
        // Coarse cells, so that many hold several blocks; and cells of more than 64 blocks,
        // whose blocks after the 64th no mask bit stands for.
        for density in [0.3, 0.002] {
            let plain = Grid::build_with_density(triangles.clone(), density);
            let boxed = Grid::build_boxed(triangles.clone(), density);
            assert_eq!(boxed.cells.unit_shift(), 0);
            let most = (0..boxed.cells.occupied())
                .map(|k| boxed.cells.blocks_of(k).len())
                .max();
            assert!(
                density > 0.01 || most > Some(MASKED_BLOCKS),
                "{most:?} blocks"
            );
            let mut cell_boxes_only = boxed.clone();
            cell_boxes_only.block_boxes.fill(cell_box::WHOLE);
            let mut rng = crate::render::sampling::Rng::new(59, 2);
            let (mut hits, mut tests) = (0, [0; 2]);
            for k in 0..20_000 {
                let mut u = || rng.uniform() * 2.0 - 1.0;
                let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 3.0 } else { 0.9 };
                let mut ray = Ray::new(origin, Vec3::new(u(), u(), u()).normalize());
                let expected = plain.intersect(&ray);
                let mut counts = [TraversalCounts::default(); 2];
                let found = boxed.intersect_counting(&ray, &mut counts[0]);
                cell_boxes_only.intersect_counting(&ray, &mut counts[1]);
                let portable = boxed.intersect_portable::<false, 0, true>(&ray, &mut ());
                for got in [found, portable] {
                    assert_eq!(got.map(|h| h.t), expected.map(|h| h.t), "ray {k}");
                    if let (Some(got), Some(expected)) = (got, expected)
                        && got.triangle != expected.triangle
                    {
                        let other = triangles[got.triangle as usize].intersect(&ray, f32::INFINITY);
                        assert_eq!(other.map(|h| h.t), Some(expected.t), "ray {k}");
                    }
                }
                hits += usize::from(expected.is_some());
                for (tests, counts) in tests.iter_mut().zip(counts) {
                    *tests += counts.tests;
                }
                ray.t_max = 1.5;
                assert_same_occlusion::<0, true>(&plain, &boxed, &ray, k);
            }
            assert!(hits > 5_000, "{hits} hits");
            assert!(
                tests[0] * 10 < tests[1] * 8,
                "density {density}: tests {tests:?}"
            );
        }
    }

    /// A ray whose direction is tiny (as a ray carried into the space of a hugely scaled
    /// instance is) or has components far below the others finds what its normalised twin
    /// finds, at the correspondingly scaled distance.
    #[test]
    fn a_ray_of_any_direction_length_finds_what_its_normalised_twin_finds() {
        let grid = Grid::build(sphere(40));
        let mut rng = crate::render::sampling::Rng::new(31, 2);
        let mut hits = 0;
        for k in 0..2_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()) * 2.5;
            let mut direction = Vec3::new(u(), u(), u()).normalize();
            if k % 3 == 0 {
                // Nearly parallel to an axis: the others a millionth of it.
                direction = Vec3::new(1.0, 1e-6 * u(), 1e-6 * u()).normalize();
            }
            let twin = Ray::new(origin, direction);
            let scale = if k % 2 == 0 { 1e-30 } else { 1e12 };
            let scaled = Ray::new(origin, direction * scale);
            let (a, b) = (grid.intersect(&twin), grid.intersect(&scaled));
            assert_eq!(a.map(|h| h.triangle), b.map(|h| h.triangle), "ray {k}");
            if let (Some(a), Some(b)) = (a, b) {
                assert!(
                    (b.t * scale / a.t - 1.0).abs() < 1e-4,
                    "ray {k}: {a:?} {b:?}"
                );
                hits += 1;
            }
        }
        assert!(hits > 100, "{hits} hits");
    }

    /// The walk alone, told where the nearest hit lies, gives out the occupied cells the
    /// query visits (for rays that miss, all of them along the ray).
    #[test]
    fn the_walk_alone_visits_the_cells_the_query_visits() {
        let grid = Grid::build(sphere(80));
        let (mut hits, mut rays) = (0, 0);
        for k in 0..2000 {
            let a = k as f32 * 0.37;
            let origin = Vec3::new(2.5 * a.cos(), 0.002 * k as f32 - 2.0, 2.5 * a.sin());
            let target = Vec3::new(0.3 * a.sin(), 0.5 * (k % 7) as f32 - 1.5, 0.0);
            let ray = Ray::new(origin, (target - origin).normalize());
            let mut counts = TraversalCounts::default();
            let hit = grid.intersect_counting(&ray, &mut counts);
            let t_stop = hit.map_or(f32::INFINITY, |h| h.t);
            assert_eq!(
                grid.walk(&ray, t_stop) as u64,
                counts.occupied,
                "ray {k}: {ray:?}"
            );
            hits += usize::from(hit.is_some());
            rays += 1;
        }
        assert!(hits > 400 && hits < rays - 400, "{hits} of {rays} rays hit");
    }
}
