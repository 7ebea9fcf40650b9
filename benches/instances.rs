//! The top level over instances: how ray cost and render cost grow with the number of
//! instances, for the instance grid (what the renderer chooses) against testing every
//! instance in turn (the list, as the renderer did before the grid), in one run.
//!
//! Run with `cargo bench --bench instances`. Single thread (the counts, not the cores, are
//! the question). Scenes: `tests/support/instances` — copies of a 288-triangle sphere over a ground,
//! one of them moving, under a constant sky.

#[path = "../tests/support/instances/mod.rs"]
mod instances;

use std::time::{Duration, Instant};

use glam::Vec3;
use gridtrace::accel::{SceneAccel, TopLevel};
use gridtrace::render::{RenderSettings, Renderer};
use gridtrace::scene::{Camera, Environment};
use instances::{field, rays};

/// Best of `repeats` timings of `f`.
fn best_of(repeats: usize, mut f: impl FnMut()) -> Duration {
    (0..repeats)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed()
        })
        .min()
        .unwrap()
}

fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    pool.install(run);
}

fn run() {
    println!(
        "| instances | rays: grid Mrays/s | list Mrays/s | grid/list | render: grid samples/s | list samples/s | grid/list |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut first_grid_rate = None;
    for count in [10, 100, 1000, 10_000] {
        let mut scene = field(count, 5);
        scene.environment = Some(Environment::constant(Vec3::splat(1.0), "bench sky"));
        let rays = rays(count, 100_000, 6);
        let grid = SceneAccel::build_with(&scene, TopLevel::Automatic);
        let list = SceneAccel::build_with(&scene, TopLevel::List);
        // The list at 10,000 instances is slow: fewer rays, same per-ray figure.
        let list_rays = &rays[..rays.len() / if count >= 1000 { 20 } else { 1 }];
        let mut sink = 0usize;
        let mut grid_time = Duration::MAX;
        let mut list_time = Duration::MAX;
        // Interleaved, best of 5 each.
        for _ in 0..5 {
            grid_time = grid_time.min(best_of(1, || {
                sink += rays.iter().filter(|r| grid.intersect(r).is_some()).count()
            }));
            list_time = list_time.min(best_of(1, || {
                sink += list_rays
                    .iter()
                    .filter(|r| list.intersect(r).is_some())
                    .count()
            }));
        }
        let grid_rate = rays.len() as f64 / grid_time.as_secs_f64() / 1e6;
        let list_rate = list_rays.len() as f64 / list_time.as_secs_f64() / 1e6;
        first_grid_rate.get_or_insert(grid_rate);

        let camera = Camera::framing(&scene.bounds(), 1.0);
        let settings = RenderSettings {
            width: 48,
            height: 48,
            samples: 0..(if count >= 1000 { 1 } else { 4 }),
            max_depth: 4,
            ..RenderSettings::default()
        };
        let samples_per_second = |top_level: TopLevel| {
            let renderer = Renderer::with_top_level(&scene, top_level);
            let mut best = 0.0f64;
            for _ in 0..3 {
                let (_, stats) = renderer.render(&camera, &settings, &|| {});
                best = best.max(stats.samples as f64 / stats.elapsed.as_secs_f64());
            }
            best
        };
        let grid_sps = samples_per_second(TopLevel::Automatic);
        let list_sps = samples_per_second(TopLevel::List);
        println!(
            "| {count} | {grid_rate:.3} | {list_rate:.4} | {:.1} | {grid_sps:.0} | {list_sps:.1} | {:.1} |",
            grid_rate / list_rate,
            grid_sps / list_sps
        );
        std::hint::black_box(sink);
    }
    if let Some(rate) = first_grid_rate {
        println!(
            "\nper-ray cost relative to 10 instances is in the grid column: {rate:.3} Mrays/s at 10"
        );
    }
}
