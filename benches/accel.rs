//! The grid against Embree 4 (`rtcIntersect1`/`rtcOccluded1`) and the obvhs CWBVH on the
//! Stanford dragon at several sizes: build time (median of 5, the three built in turn),
//! memory per triangle (each structure's own allocation: Embree's memory monitor, obvhs'
//! node and index arrays, the grid's arrays), and single-thread throughput on five ray
//! sets — rays from outside, a pinhole camera's rays, bounce rays from the surface, shadow
//! segments (`occluded`: the bounce rays cut to random lengths), and light segments (shadow
//! segments as light sampling makes them, from the surface to a square light above it).
//!
//! Timing: each set is cut into chunks of 10,000 rays; for every chunk the three structures
//! take turns (in rotating order), each keeping the best of 7 repeats, so drifts of the
//! machine's speed touch all three alike. That is one run; the ratios are reported as the
//! median and the range over 5 runs. Then the grid's own counters per ray (for shadow
//! segments too), where its triangle tests are made ([`tests_per_cell`]), each query's
//! time per ray with caches cold and warm ([`cold_and_warm`]), the grid's time split
//! between its walk and its triangles ([`Grid::walk`]) as in the table and with caches
//! warm (what each costs in computation alone), for rays from outside the grid's box the
//! share of the query spent approaching the surface ([`first_cell_starts`]), the ratio to
//! Embree over the rays that hit the mesh and over those that miss it (the shadow segments
//! that are blocked and those that pass), each part timed alone, and the grid's speed-up on
//! all threads (bounce rays, each timing about 0.2 s long). The camera rays, which come in
//! tiles of 8 × 8, are also timed against Embree's widest native packet query
//! (`rtcIntersect16` or `8`): row `camera-vs-16`, the grid's single rays over Embree's
//! packets; and the grid of the camera's eye ([`ViewGrid`], four columns per ray, its build
//! timed apart, its answers compared with the grid's): rows `view-camera` (over Embree's
//! `rtcIntersect1`) and `view-camera-vs-16` (over its packets).
//!
//! Run with `cargo bench --bench accel` after `tools/dev/setup.sh`. Environment:
//! `ACCEL_BENCH_MODELS` (comma-separated files of data/dragon, default the smallest, a
//! middle one and the full dragon), `ACCEL_BENCH_RAYS` (rays per set, default 100,000),
//! `ACCEL_BENCH_RUNS` (default 5), `ACCEL_BENCH_DENSITY` (the grid's cells per triangle),
//! `ACCEL_BENCH_VIEW_COLUMNS` (the view grid's columns per camera ray, default 4).

#[path = "../tests/support/oracles/mod.rs"]
mod oracles;

use std::ops::Range;
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use gridtrace::accel::{Grid, Ray, TraversalCounts, TraversalStats, View, ViewGrid};
use gridtrace::geometry::Aabb;
use gridtrace::load::ply;
use oracles::embree::Embree;
use oracles::rays::{bounce_rays, camera_rays, light_segments, outside_rays, segments};
use oracles::{Mesh, Obvhs, dragon_path};
use rayon::prelude::*;

const CHUNK: usize = 10_000;
const REPEATS: usize = 7;

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration) {
    let start = Instant::now();
    let value = f();
    (value, start.elapsed())
}

/// Median and range of a few figures.
fn summary(mut values: Vec<f64>) -> (f64, f64, f64) {
    values.sort_by(f64::total_cmp);
    (
        values[values.len() / 2],
        values[0],
        values[values.len() - 1],
    )
}

type Query<'a> = Box<dyn Fn(&Ray) -> bool + 'a>;

/// A query over a run of rays, answering how many hit: for packet queries.
type ChunkQuery<'a> = Box<dyn Fn(&[Ray]) -> usize + 'a>;

/// One run over a ray set: Mrays/s of each query, interleaved chunk by chunk.
fn run_once(rays: &[Ray], queries: &[Query], run: usize) -> Vec<f64> {
    let chunked: Vec<ChunkQuery> = queries
        .iter()
        .map(|q| Box::new(move |c: &[Ray]| c.iter().filter(|r| q(r)).count()) as ChunkQuery)
        .collect();
    run_chunks(rays, &chunked, run)
}

/// [`run_once`] for queries that take a chunk of rays at a time.
fn run_chunks(rays: &[Ray], queries: &[ChunkQuery], run: usize) -> Vec<f64> {
    let mut total = vec![Duration::ZERO; queries.len()];
    for (c, chunk) in rays.chunks(CHUNK).enumerate() {
        for k in 0..queries.len() {
            let q = (k + c + run) % queries.len();
            let best = (0..REPEATS)
                .map(|_| {
                    let (hits, t) = timed(|| queries[q](chunk));
                    std::hint::black_box(hits);
                    t
                })
                .min()
                .unwrap();
            total[q] += best;
        }
    }
    total
        .iter()
        .map(|t| rays.len() as f64 / t.as_secs_f64() / 1e6)
        .collect()
}

/// Columns of the view grid per camera ray unless `ACCEL_BENCH_VIEW_COLUMNS` says
/// otherwise: as the renderer's per pixel.
const VIEW_COLUMNS_PER_RAY: usize = 4;

/// The view ([`View`]) of the eye all of `rays` start from, over a window that holds every
/// ray's direction, [`VIEW_COLUMNS_PER_RAY`] columns per ray at most.
fn view_of_rays(rays: &[Ray]) -> View {
    let eye = rays[0].origin;
    let forward = rays
        .iter()
        .map(|r| r.direction.normalize())
        .sum::<Vec3>()
        .normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let on_plane = |d: Vec3| Vec2::new(d.dot(right), d.dot(up)) / d.dot(forward);
    let (lo, hi) = rays
        .iter()
        .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(lo, hi), r| {
            let p = on_plane(r.direction);
            (lo.min(p), hi.max(p))
        });
    let pad = 0.01 * (hi - lo);
    View {
        eye,
        right,
        up,
        forward,
        lo: lo - pad,
        hi: hi + pad,
        max_columns: (env_or("ACCEL_BENCH_VIEW_COLUMNS", VIEW_COLUMNS_PER_RAY) * rays.len()) as u32,
    }
}

/// Camera rays (in tiles of 8 × 8, [`camera_rays`]): the grid's single rays against
/// Embree's widest native packet query (`rtcIntersect16` or `8`) besides its
/// `rtcIntersect1`, each packet a run of consecutive rays of one tile, and the view grid of
/// the camera's eye ([`ViewGrid`], its build timed apart). Table rows as the main table's
/// (the grid, then the view grid, over Embree's packets) and notes.
fn camera_rows(
    model: &str,
    n: usize,
    grid: &Grid,
    embree: &Embree,
    rays: &[Ray],
    runs: usize,
) -> (Vec<String>, Vec<String>) {
    let width = embree.native_packet();
    let embree_packets = |c: &[Ray]| {
        let mut hits = [None; 16];
        c.chunks(width)
            .map(|p| {
                let hits = &mut hits[..p.len()];
                match width {
                    16 => embree.intersect16(p, hits),
                    8 => embree.intersect8(p, hits),
                    _ => hits
                        .iter_mut()
                        .zip(p)
                        .for_each(|(h, r)| *h = embree.intersect(r)),
                }
                hits.iter().filter(|h| h.is_some()).count()
            })
            .sum()
    };
    let view = view_of_rays(rays);
    let builds: Vec<(ViewGrid, Duration)> = (0..5)
        .map(|_| timed(|| ViewGrid::build(&[grid], view).expect("the dragon lies ahead")))
        .collect();
    let build_s = summary(builds.iter().map(|b| b.1.as_secs_f64()).collect()).0;
    let view_grid = &builds[0].0;
    // A ray the view grid leaves (a tie at its nearest distance) is the grid's to answer.
    let view_then_grid = |r: &Ray| match view_grid.intersect(r) {
        Some(hit) => hit.map(|h| (h.t, h.u, h.v, h.triangle)),
        None => grid.intersect(r).map(|h| (h.t, h.u, h.v, h.triangle)),
    };
    let left_to_grid = rays
        .iter()
        .filter(|r| view_grid.intersect(r).is_none())
        .count();
    let differing = rays
        .iter()
        .filter(|r| view_then_grid(r) != grid.intersect(r).map(|h| (h.t, h.u, h.v, h.triangle)))
        .count();
    let queries: Vec<ChunkQuery> = vec![
        Box::new(|c: &[Ray]| c.iter().filter(|r| grid.intersect(r).is_some()).count()),
        Box::new(|c: &[Ray]| c.iter().filter(|r| embree.intersect(r).is_some()).count()),
        Box::new(embree_packets),
        Box::new(|c: &[Ray]| c.iter().filter(|r| view_then_grid(r).is_some()).count()),
    ];
    let rates: Vec<Vec<f64>> = (0..runs)
        .map(|run| run_chunks(rays, &queries, run))
        .collect();
    let median = |q: usize| summary(rates.iter().map(|r| r[q]).collect()).0;
    let row = |name: &str, q: usize, over: usize| {
        let (ratio, lo, hi) = summary(rates.iter().map(|r| r[q] / r[over]).collect());
        format!(
            "| {model} | {n} | {name} | {:.3} | {:.3} | – | {ratio:.2} ({lo:.2}–{hi:.2}) | – |",
            median(q),
            median(over)
        )
    };
    let rows = vec![
        row(&format!("camera-vs-{width}"), 0, 2),
        row("view-camera", 3, 1),
        row(&format!("view-camera-vs-{width}"), 3, 2),
    ];
    let bytes = view_grid.bytes();
    let notes = vec![
        format!(
            "{model}, camera rays (8 × 8 tiles), Mrays/s (median of {runs}): grid {:.3}, view grid {:.3}, Embree rtcIntersect1 {:.3}, Embree packets of {width} {:.3}",
            median(0),
            median(3),
            median(1),
            median(2)
        ),
        format!(
            "{model}, view grid: {}x{} columns, build {build_s:.4} s (median of 5), {:.1} bytes/triangle; {differing} of {} camera rays answered otherwise than by the grid (t, u, v or triangle), {left_to_grid} left to the grid",
            view_grid.columns().x,
            view_grid.columns().y,
            bytes as f64 / n as f64,
            rays.len()
        ),
    ];
    (rows, notes)
}

/// The medians over `runs` runs of the two figures `run_pair(run)` gives.
fn medians_of_runs(runs: usize, run_pair: impl Fn(usize) -> (f64, f64)) -> (f64, f64) {
    let pairs: Vec<(f64, f64)> = (0..runs).map(run_pair).collect();
    (
        summary(pairs.iter().map(|p| p.0).collect()).0,
        summary(pairs.iter().map(|p| p.1).collect()).0,
    )
}

/// Two queries over the same `count` rays, ns per ray of each: every chunk of `CHUNK` rays
/// timed as in [`run_once`] (best of `REPEATS`, the two in rotating order); `query(q,
/// range)` runs query `q` over the rays in `range`.
fn time_two(count: usize, run: usize, query: impl Fn(usize, Range<usize>) -> usize) -> (f64, f64) {
    let mut total = [Duration::ZERO; 2];
    for c in 0..count.div_ceil(CHUNK) {
        let range = c * CHUNK..((c + 1) * CHUNK).min(count);
        for k in 0..2 {
            let q = (k + c + run) % 2;
            let best = (0..REPEATS)
                .map(|_| {
                    let (answers, t) = timed(|| query(q, range.clone()));
                    std::hint::black_box(answers);
                    t
                })
                .min()
                .unwrap();
            total[q] += best;
        }
    }
    let per_ray = |t: Duration| t.as_secs_f64() * 1e9 / count as f64;
    (per_ray(total[0]), per_ray(total[1]))
}

/// The grid's time per ray split between its walk and its triangles, ns per ray of the
/// query and of the walk alone to where the query's hit lies (`stops`, [`Grid::walk`]).
fn walk_split(grid: &Grid, rays: &[Ray], stops: &[f32], run: usize) -> (f64, f64) {
    time_two(rays.len(), run, |q, range| match q {
        0 => rays[range]
            .iter()
            .filter(|r| grid.intersect(r).is_some())
            .count(),
        _ => rays[range.clone()]
            .iter()
            .zip(&stops[range])
            .map(|(r, &s)| grid.walk(r, s))
            .sum(),
    })
}

/// Each ray of `rays` begun just before the first occupied cell it meets (`t_min` moved
/// there; to ∞ for a ray that meets none, which then costs only the clip to the box), and
/// how many meet none: an oracle for the time the grid spends on its approach to the
/// surface. Found by bisection on `t_min` over [`Grid::walk`]: the walk gives out the
/// same number of occupied cells until `t_min` passes the first one's exit, and that
/// cell's entry lies within one cell diagonal before it. No hit lies before the first
/// occupied cell, so the answers stay the same (checked).
fn first_cell_starts(grid: &Grid, rays: &[Ray]) -> (Vec<Ray>, usize) {
    let bounds = grid.bounds();
    let mut none = 0;
    let starts = rays
        .iter()
        .map(|ray| {
            let mut start = *ray;
            let cells = grid.walk(ray, f32::INFINITY);
            if cells == 0 {
                none += 1;
                start.t_min = f32::INFINITY;
                return start;
            }
            let length = ray.direction.length();
            // Past this the ray is beyond the box.
            let beyond =
                ((bounds.center() - ray.origin).length() + bounds.extent().length()) / length;
            let (mut lo, mut hi) = (ray.t_min, beyond);
            for _ in 0..32 {
                let mid = 0.5 * (lo + hi);
                start.t_min = mid;
                if grid.walk(&start, f32::INFINITY) == cells {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            start.t_min = (lo - 1.01 * grid.cell_size().length() / length).max(ray.t_min);
            assert_eq!(
                grid.intersect(&start),
                grid.intersect(ray),
                "a ray begun at its first occupied cell found another hit: {ray:?}"
            );
            start
        })
        .collect();
    (starts, none)
}

/// The grid's ns per ray over `rays` and over `starts` (the same rays begun elsewhere,
/// [`first_cell_starts`]).
fn approach_split(grid: &Grid, rays: &[Ray], starts: &[Ray], run: usize) -> (f64, f64) {
    time_two(rays.len(), run, |q, range| {
        let set = if q == 0 { rays } else { starts };
        set[range]
            .iter()
            .filter(|r| grid.intersect(r).is_some())
            .count()
    })
}

/// The grid over `mesh`, with `density` cells per triangle or the density it chooses.
fn build_grid(mesh: &Mesh, density: Option<f32>) -> Grid {
    match density {
        Some(d) => Grid::from_mesh_with_density(mesh.positions.clone(), &mesh.indices, d),
        None => Grid::from_mesh(mesh.positions.clone(), &mesh.indices),
    }
}

/// Traces `ray` through `grid` (a shadow query if `occlusion`, else a closest-hit query),
/// reporting its work to `stats`; true when it is blocked or hits.
fn trace_counting(
    grid: &Grid,
    ray: &Ray,
    occlusion: bool,
    stats: &mut impl TraversalStats,
) -> bool {
    if occlusion {
        grid.occluded_counting(ray, stats)
    } else {
        grid.intersect_counting(ray, stats).is_some()
    }
}

/// The grid's counters per ray over `rays` (closest-hit queries, or shadow queries if
/// `occlusion`), as a phrase.
fn counters(grid: &Grid, rays: &[Ray], occlusion: bool) -> String {
    let mut counts = TraversalCounts::default();
    let mut hits = 0usize;
    for r in rays {
        hits += usize::from(trace_counting(grid, r, occlusion, &mut counts));
    }
    let per_ray = |x: u64| x as f64 / rays.len() as f64;
    format!(
        "{:.1} cells stepped ({:.1} occupied macrocells entered, {:.1} leaps over empty macrocells, {:.1} over empty cubes of cells, {:.1} plain steps), {:.1} occupied cells visited, {:.1} pauses of the walk ahead, {:.1} triangle tests, {:.2} {} per ray",
        per_ray(counts.cells),
        per_ray(counts.macrocell_entries),
        per_ray(counts.macrocell_leaps),
        per_ray(counts.cell_leaps),
        per_ray(counts.plain_steps),
        per_ray(counts.occupied),
        per_ray(counts.pauses),
        per_ray(counts.tests),
        hits as f64 / rays.len() as f64,
        if occlusion { "occluded" } else { "hits" }
    )
}

/// The triangle tests made in each occupied cell a query visits (the tests reported after
/// the cell is given out, up to the next one).
#[derive(Default)]
struct TestsPerCell {
    open: Option<u32>,
    cells: Vec<u32>,
}

impl TraversalStats for TestsPerCell {
    type Lent<'a> = &'a mut TestsPerCell;
    fn lend(&mut self) -> &mut TestsPerCell {
        self
    }
    fn visit_occupied(&mut self) {
        self.cells.extend(self.open.replace(0));
    }
    fn test_triangles(&mut self, count: usize) {
        if let Some(open) = self.open.as_mut() {
            *open += count as u32;
        }
    }
}

/// Where the triangle tests over `rays` are made: the share of them made in occupied cells
/// where a ray tests more than 16, 24, 32 and 48 triangles (and those cells' share of the
/// visits), as a phrase. Refining crowded cells can only save tests made in such cells.
fn tests_per_cell(grid: &Grid, rays: &[Ray], occlusion: bool) -> String {
    let mut stats = TestsPerCell::default();
    for r in rays {
        trace_counting(grid, r, occlusion, &mut stats);
        stats.cells.extend(stats.open.take());
    }
    let tests: u64 = stats.cells.iter().map(|&n| u64::from(n)).sum();
    let visits = stats.cells.len().max(1) as f64;
    let shares: Vec<String> = [16, 24, 32, 48]
        .iter()
        .map(|&limit| {
            let crowded = stats.cells.iter().filter(|&&n| n > limit);
            let made: u64 = crowded.clone().map(|&n| u64::from(n)).sum();
            format!(
                "more than {limit}: {:.0} % of tests in {:.0} % of visits",
                100.0 * made as f64 / tests.max(1) as f64,
                100.0 * crowded.count() as f64 / visits
            )
        })
        .collect();
    format!(
        "{:.1} tests per occupied cell visited; cells where a ray tests {}",
        tests as f64 / visits,
        shares.join(", ")
    )
}

/// How many times in a row each ray is traced for the warm figure.
const WARM_REPEATS: usize = 8;

/// Nanoseconds per ray of each query, cold and warm, for one run: every ray traced once
/// (as a stream of unrelated rays leaves the caches), then every ray `WARM_REPEATS` times
/// in a row (all but the first find what the ray needs in cache), chunk by chunk with the
/// queries in rotating order. Warm is (R·T_R − T_1)/(R − 1); cold minus warm is the time
/// a ray waits for memory.
fn cold_and_warm(rays: &[Ray], queries: &[Query], run: usize) -> Vec<(f64, f64)> {
    cold_and_warm_of(rays.len(), queries.len(), |q, i| queries[q](&rays[i]), run)
}

/// [`cold_and_warm`] for `queries` queries over `count` rays, `query(q, i)` asking query
/// `q` about ray `i`.
fn cold_and_warm_of(
    count: usize,
    queries: usize,
    query: impl Fn(usize, usize) -> bool,
    run: usize,
) -> Vec<(f64, f64)> {
    let mut once = vec![Duration::ZERO; queries];
    let mut repeated = vec![Duration::ZERO; queries];
    for (c, start) in (0..count).step_by(CHUNK).enumerate() {
        let chunk = start..(start + CHUNK).min(count);
        for k in 0..queries {
            let q = (k + c + run) % queries;
            let (hits, t) = timed(|| chunk.clone().filter(|&i| query(q, i)).count());
            std::hint::black_box(hits);
            once[q] += t;
            let (hits, t) = timed(|| {
                chunk
                    .clone()
                    .flat_map(|i| std::iter::repeat_n(i, WARM_REPEATS))
                    .filter(|&i| query(q, i))
                    .count()
            });
            std::hint::black_box(hits);
            repeated[q] += t;
        }
    }
    let n = count as f64;
    let r = WARM_REPEATS as f64;
    once.iter()
        .zip(&repeated)
        .map(|(t1, tr)| {
            let cold = t1.as_secs_f64() * 1e9 / n;
            let all = tr.as_secs_f64() * 1e9 / n;
            (cold, (all - cold) / (r - 1.0))
        })
        .collect()
}

fn main() {
    let models: String = env_or(
        "ACCEL_BENCH_MODELS",
        "dragon_vrip_res4.ply.gz,dragon_vrip_res2.ply.gz,dragon_vrip.ply.gz".to_string(),
    );
    let count: usize = env_or("ACCEL_BENCH_RAYS", 100_000);
    let runs: usize = env_or("ACCEL_BENCH_RUNS", 5);
    // Unset: the density the grid chooses for each mesh.
    let density: Option<f32> = std::env::var("ACCEL_BENCH_DENSITY")
        .ok()
        .and_then(|v| v.parse().ok());
    println!(
        "{count} rays per set, {runs} runs, chunks of {CHUNK} rays, best of {REPEATS} per chunk; {} threads for the scaling figure\n",
        rayon::current_num_threads()
    );
    println!(
        "| model | triangles | rays | grid Mrays/s | Embree | CWBVH | grid/Embree median (range) | grid/CWBVH median (range) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut notes = Vec::new();
    for model in models.split(',') {
        let (positions, indices) = ply::read_mesh(&dragon_path(model)).expect("read the dragon");
        let mesh = Mesh { positions, indices };
        let n = mesh.indices.len();
        let triangles = mesh.triangles();
        // Builds, median of 5, the three structures in turn (the builds use all threads,
        // as the renderer's do), so drifts of the machine's speed touch all three alike.
        // One untimed round first, and each round begun by the next structure: the first
        // builds of a process pay for its first touch of memory and of the worker threads,
        // which later builds reuse (with the grid always built first, a run's first
        // process read it 1.13-1.31 of Embree's time, the others 0.80-0.94).
        let builds: [&dyn Fn(); 3] = [
            &|| drop(build_grid(&mesh, density)),
            &|| drop(Embree::build(&mesh)),
            &|| drop(Obvhs::build(&mesh)),
        ];
        builds.iter().for_each(|build| build());
        let mut build_times = [vec![], vec![], vec![]];
        for round in 0..5 {
            for k in (0..3).map(|k| (k + round) % 3) {
                build_times[k].push(timed(builds[k]).1.as_secs_f64());
            }
        }
        let [grid_build, embree_build, bvh_build] = build_times.map(|t| summary(t).0);
        let grid = build_grid(&mesh, density);
        let embree = Embree::build(&mesh);
        let bvh = Obvhs::build(&mesh);
        let stats = grid.stats();
        notes.push(format!(
            "{model}: build s grid {grid_build:.3}, Embree {embree_build:.3}, CWBVH {bvh_build:.3}; bytes/triangle grid {:.1}, Embree {:.1}, CWBVH {:.1}; grid {}x{}x{} cells, {:.2} references/triangle",
            stats.bytes as f64 / n as f64,
            embree.bytes as f64 / n as f64,
            bvh.bytes() as f64 / n as f64,
            stats.resolution.x,
            stats.resolution.y,
            stats.resolution.z,
            stats.references as f64 / stats.triangles as f64,
        ));

        let bounds = Aabb::from_points(mesh.positions.iter().copied());
        let bounce = bounce_rays(&triangles, count, 22);
        let shadow = segments(&bounce, 0.3 * bounds.extent().length(), 23);
        let sets: [(&str, Vec<Ray>, bool); 5] = [
            ("outside", outside_rays(&bounds, count, 21), false),
            ("camera", camera_rays(&bounds, count), false),
            ("bounce", bounce, false),
            ("shadow", shadow, true),
            (
                "light",
                light_segments(&triangles, &bounds, count, 24),
                true,
            ),
        ];
        for (name, rays, occlusion) in &sets {
            let queries: Vec<Query> = if *occlusion {
                vec![
                    Box::new(|r: &Ray| grid.occluded(r)),
                    Box::new(|r: &Ray| embree.occluded(r)),
                    Box::new(|r: &Ray| bvh.occluded(r)),
                ]
            } else {
                vec![
                    Box::new(|r: &Ray| grid.intersect(r).is_some()),
                    Box::new(|r: &Ray| embree.intersect(r).is_some()),
                    Box::new(|r: &Ray| bvh.intersect(r).is_some()),
                ]
            };
            // Queries run on this thread alone: single-thread figures.
            let rates: Vec<Vec<f64>> = (0..runs).map(|run| run_once(rays, &queries, run)).collect();
            let (g, _, _) = summary(rates.iter().map(|r| r[0]).collect());
            let (e, _, _) = summary(rates.iter().map(|r| r[1]).collect());
            let (b, _, _) = summary(rates.iter().map(|r| r[2]).collect());
            let (ge, ge_lo, ge_hi) = summary(rates.iter().map(|r| r[0] / r[1]).collect());
            let (gb, gb_lo, gb_hi) = summary(rates.iter().map(|r| r[0] / r[2]).collect());
            println!(
                "| {model} | {n} | {name} | {g:.3} | {e:.3} | {b:.3} | {ge:.2} ({ge_lo:.2}–{ge_hi:.2}) | {gb:.2} ({gb_lo:.2}–{gb_hi:.2}) |"
            );
            let times: Vec<Vec<(f64, f64)>> = (0..runs)
                .map(|run| cold_and_warm(rays, &queries, run))
                .collect();
            let [grid_t, embree_t, bvh_t] = [0, 1, 2].map(|q| {
                let (cold, ..) = summary(times.iter().map(|t| t[q].0).collect());
                let (warm, ..) = summary(times.iter().map(|t| t[q].1).collect());
                (cold, warm)
            });
            notes.push(format!(
                "{model}, {name} rays, ns per ray cold / warm (median of {runs}): grid {:.0} / {:.0}, Embree {:.0} / {:.0}, CWBVH {:.0} / {:.0}; waiting for memory (cold − warm): grid {:.0}, Embree {:.0}",
                grid_t.0,
                grid_t.1,
                embree_t.0,
                embree_t.1,
                bvh_t.0,
                bvh_t.1,
                grid_t.0 - grid_t.1,
                embree_t.0 - embree_t.1,
            ));
            notes.push(format!(
                "{model}, {name} rays: {}",
                tests_per_cell(&grid, rays, *occlusion)
            ));
            if !*occlusion {
                let stops: Vec<f32> = rays
                    .iter()
                    .map(|r| grid.intersect(r).map_or(f32::INFINITY, |h| h.t))
                    .collect();
                let (query, walk) =
                    medians_of_runs(runs, |run| walk_split(&grid, rays, &stops, run));
                notes.push(format!(
                    "{model}, {name} rays, grid ns per ray as in the table (median of {runs}): query {query:.0}, of which the walk alone {walk:.0} ({:.0} %), the triangles' reads and tests {:.0}",
                    100.0 * walk / query,
                    query - walk
                ));
                // The same split with caches warm: what the walk and the triangles cost
                // in computation alone.
                let warm: Vec<Vec<(f64, f64)>> = (0..runs)
                    .map(|run| {
                        let query = |q: usize, i: usize| match q {
                            0 => grid.intersect(&rays[i]).is_some(),
                            _ => grid.walk(&rays[i], stops[i]) > 0,
                        };
                        cold_and_warm_of(rays.len(), 2, query, run)
                    })
                    .collect();
                let (query, ..) = summary(warm.iter().map(|t| t[0].1).collect());
                let (walk, ..) = summary(warm.iter().map(|t| t[1].1).collect());
                notes.push(format!(
                    "{model}, {name} rays, grid ns per ray warm (median of {runs}): query {query:.0}, of which the walk alone {walk:.0} ({:.0} %), the triangles' tests {:.0}; Embree's whole query {:.0}",
                    100.0 * walk / query,
                    query - walk,
                    embree_t.1
                ));
                // For rays from outside the grid's box: what their approach to the surface
                // costs.
                let outside = |r: &Ray| {
                    let (b, o) = (grid.bounds(), r.origin);
                    o.cmplt(b.min).any() || o.cmpgt(b.max).any()
                };
                if rays.iter().all(outside) {
                    let (starts, none) = first_cell_starts(&grid, rays);
                    let (query, begun) =
                        medians_of_runs(runs, |run| approach_split(&grid, rays, &starts, run));
                    notes.push(format!(
                        "{model}, {name} rays, the approach to the surface: begun at its first occupied cell (an oracle; {none} of {} rays meet none and cost only the clip), the grid takes {begun:.0} ns per ray against the query's {query:.0} (median of {runs}): the approach is {:.0} % of the query",
                        rays.len(),
                        100.0 * (1.0 - begun / query)
                    ));
                }
            }
            notes.push(format!(
                "{model}, {name} rays: {}",
                counters(&grid, rays, *occlusion)
            ));
            // Rays that hit the mesh and rays that miss it (shadow segments that are
            // blocked and those that are not), by Embree's answer, cost the two
            // structures very differently: each part timed on its own, grid against
            // Embree, like the table.
            let (hit, miss): (Vec<Ray>, Vec<Ray>) = rays.iter().partition(|r| {
                if *occlusion {
                    embree.occluded(r)
                } else {
                    embree.intersect(r).is_some()
                }
            });
            let parts = if *occlusion {
                [("are blocked by", &hit), ("pass", &miss)]
            } else {
                [("hit", &hit), ("miss", &miss)]
            };
            for (part, subset) in parts {
                if subset.is_empty() {
                    continue;
                }
                let rates: Vec<Vec<f64>> = (0..runs)
                    .map(|run| run_once(subset, &queries[..2], run))
                    .collect();
                let (ratio, lo, hi) = summary(rates.iter().map(|r| r[0] / r[1]).collect());
                let (g, ..) = summary(rates.iter().map(|r| 1e3 / r[0]).collect());
                let (e, ..) = summary(rates.iter().map(|r| 1e3 / r[1]).collect());
                notes.push(format!(
                    "{model}, {name} rays that {part} the mesh ({} of {}): grid/Embree {ratio:.2} ({lo:.2}–{hi:.2}), ns per ray grid {g:.0}, Embree {e:.0}; {}",
                    subset.len(),
                    rays.len(),
                    counters(&grid, subset, *occlusion)
                ));
            }
        }
        let (rows, camera_notes) = camera_rows(model, n, &grid, &embree, &sets[1].1, runs);
        rows.iter().for_each(|row| println!("{row}"));
        notes.extend(camera_notes);
        // Scaling of the grid over all threads, best of 5, each timing the ray set traced
        // as many times over as make it last about 0.2 s on one thread (on the small
        // meshes one pass takes a few milliseconds, too short for thread start-up and the
        // last chunks' imbalance not to count).
        let rays = &sets[2].1;
        let trace = |parallel: bool| {
            if parallel {
                rays.par_chunks(1024)
                    .map(|c| c.iter().filter(|r| grid.intersect(r).is_some()).count())
                    .sum::<usize>()
            } else {
                rays.iter().filter(|r| grid.intersect(r).is_some()).count()
            }
        };
        let passes = (0.2 / timed(|| trace(false)).1.as_secs_f64())
            .ceil()
            .max(1.0) as usize;
        let speed = |parallel: bool| {
            (0..5)
                .map(|_| timed(|| (0..passes).map(|_| trace(parallel)).sum::<usize>()).1)
                .min()
                .unwrap()
        };
        let (one, all) = (speed(false), speed(true));
        notes.push(format!(
            "{model}: grid on bounce rays, {} threads / 1 thread: {:.2}×",
            rayon::current_num_threads(),
            one.as_secs_f64() / all.as_secs_f64()
        ));
    }
    println!();
    for note in notes {
        println!("{note}");
    }
}
