//! The grid against Embree 4 (`rtcIntersect1`) and the obvhs CWBVH on the full Stanford
//! dragon: build time, memory, and single-ray throughput on one thread and on all threads,
//! for rays from outside and for bounce rays, with the ratios measured in the same run.
//!
//! Run with `cargo bench --bench accel` after `tools/setup-dev.sh`. Environment:
//! `ACCEL_BENCH_RAYS` (rays per set, default 1,000,000) and `ACCEL_BENCH_MODEL` (a file name
//! from data/dragon, default the full dragon).

#[path = "../tests/oracles/mod.rs"]
mod oracles;

use std::time::{Duration, Instant};

use gridtrace::accel::{Grid, Ray, TraversalCounts};
use gridtrace::load::ply;
use gridtrace::scene::Aabb;
use oracles::embree::Embree;
use oracles::rays::{bounce_rays, outside_rays};
use oracles::{Mesh, Obvhs, dragon_path};
use rayon::prelude::*;

fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration) {
    let start = Instant::now();
    let value = f();
    (value, start.elapsed())
}

/// Mrays/s of `query` over `rays`: best of three runs, on one thread or on all.
fn throughput(rays: &[Ray], parallel: bool, query: &(dyn Fn(&Ray) -> bool + Sync)) -> (f64, usize) {
    let mut best = Duration::MAX;
    let mut hits = 0;
    for _ in 0..3 {
        let (h, t) = timed(|| {
            if parallel {
                rays.par_chunks(4096)
                    .map(|c| c.iter().filter(|r| query(r)).count())
                    .sum()
            } else {
                rays.iter().filter(|r| query(r)).count()
            }
        });
        best = best.min(t);
        hits = h;
    }
    (rays.len() as f64 / best.as_secs_f64() / 1e6, hits)
}

fn main() {
    let count: usize = std::env::var("ACCEL_BENCH_RAYS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let model = std::env::var("ACCEL_BENCH_MODEL").unwrap_or_else(|_| "dragon_vrip.ply.gz".into());
    let threads = rayon::current_num_threads();
    let ((positions, indices), load) =
        timed(|| ply::read_mesh(&dragon_path(&model)).expect("read the dragon"));
    let mesh = Mesh { positions, indices };
    let n = mesh.indices.len();
    println!(
        "{model}: {n} triangles, {} vertices (read in {:.2} s); {count} rays per set; {threads} threads",
        mesh.positions.len(),
        load.as_secs_f64()
    );

    let triangles = mesh.triangles();
    let density: f32 = std::env::var("ACCEL_BENCH_DENSITY")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(gridtrace::accel::grid::DEFAULT_DENSITY);
    let (grid, grid_build) =
        timed(|| Grid::from_mesh_with_density(mesh.positions.clone(), &mesh.indices, density));
    let (embree, embree_build) = timed(|| Embree::build(&mesh));
    let (bvh, bvh_build) = timed(|| Obvhs::build(&mesh));

    let stats = grid.stats();
    println!();
    println!("| structure | build (s) | bytes/triangle |");
    println!("|---|---|---|");
    println!(
        "| grid | {:.3} | {:.1} |",
        grid_build.as_secs_f64(),
        stats.bytes as f64 / n as f64
    );
    println!(
        "| Embree 4 | {:.3} | {:.1} |",
        embree_build.as_secs_f64(),
        embree.bytes as f64 / n as f64
    );
    println!(
        "| obvhs CWBVH | {:.3} | {:.1} |",
        bvh_build.as_secs_f64(),
        bvh.bytes() as f64 / n as f64
    );
    println!(
        "\ngrid: resolution {}x{}x{} = {} cells, {:.2} references/triangle, {:.1} % empty cells",
        stats.resolution.x,
        stats.resolution.y,
        stats.resolution.z,
        stats.cells,
        stats.references as f64 / stats.triangles as f64,
        100.0 * stats.empty_fraction
    );

    let bounds = Aabb::from_points(mesh.positions.iter().copied());
    let sets = [
        ("outside", outside_rays(&bounds, count, 21)),
        ("bounce", bounce_rays(&triangles, count, 22)),
    ];
    println!();
    println!(
        "| rays | threads | grid Mrays/s | Embree Mrays/s | CWBVH Mrays/s | grid/Embree | grid/CWBVH |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut counts_lines = Vec::new();
    for (name, rays) in &sets {
        for parallel in [false, true] {
            let (g, gh) = throughput(rays, parallel, &|r| grid.intersect(r).is_some());
            let (e, eh) = throughput(rays, parallel, &|r| embree.intersect(r).is_some());
            let (b, bh) = throughput(rays, parallel, &|r| bvh.intersect(r).is_some());
            if !parallel {
                // Hit counts may differ by a few edge grazes; tests/accel_cross_check.rs says why.
                counts_lines.push(format!(
                    "{name} rays hit: grid {gh}, Embree {eh}, CWBVH {bh}"
                ));
            }
            println!(
                "| {name} | {} | {g:.3} | {e:.3} | {b:.3} | {:.2} | {:.2} |",
                if parallel { threads } else { 1 },
                g / e,
                g / b
            );
        }
        let mut counts = TraversalCounts::default();
        for r in rays {
            grid.intersect_counting(r, &mut counts);
        }
        counts_lines.push(format!(
            "grid, {name} rays: {:.1} cells visited and {:.1} triangle tests per ray",
            counts.cells as f64 / rays.len() as f64,
            counts.tests as f64 / rays.len() as f64
        ));
    }
    println!();
    for line in counts_lines {
        println!("{line}");
    }
}
