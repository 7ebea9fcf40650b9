//! In-process A/B of the grid walks (the macrocell walk of `grid/walk.rs` against the
//! cell walk of `grid/traverse.rs`), chunk by chunk: `cargo run --release --example walkprof`.
#[path = "../tests/oracles/mod.rs"]
mod oracles;
use gridtrace::accel::grid::USE_SEGMENT_MASK;
use gridtrace::accel::{Grid, Ray};
use gridtrace::load::ply;
use gridtrace::scene::Aabb;
use oracles::rays::{bounce_rays, outside_rays, segments};
use oracles::{Mesh, dragon_path};
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

fn main() {
    let models = std::env::var("M").unwrap_or("dragon_vrip_res4.ply.gz,dragon_vrip.ply.gz".into());
    let reps: usize = std::env::var("R")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    for model in models.split(',') {
        let (positions, indices) = ply::read_mesh(&dragon_path(model)).unwrap();
        let mesh = Mesh { positions, indices };
        let grid = Grid::from_mesh(mesh.positions.clone(), &mesh.indices);
        let bounds = Aabb::from_points(mesh.positions.iter().copied());
        let bounce = bounce_rays(&mesh.triangles(), 30000, 22);
        let shadow = segments(&bounce, 0.3 * bounds.extent().length(), 23);
        let sets: [(&str, Vec<Ray>); 3] = [
            ("outside", outside_rays(&bounds, 30000, 21)),
            ("bounce", bounce),
            ("shadow", shadow),
        ];
        for (name, rays) in &sets {
            let occl = *name == "shadow";
            let mut total = [Duration::ZERO; 2];
            for rep in 0..reps {
                for chunk in rays.chunks(2000) {
                    for k in 0..2 {
                        let new = (k + rep) % 2 == 0;
                        USE_SEGMENT_MASK.store(new, Relaxed);
                        let t = Instant::now();
                        let mut hits = 0;
                        for r in chunk {
                            hits += if occl {
                                grid.occluded(r)
                            } else {
                                grid.intersect(r).is_some()
                            } as usize;
                        }
                        std::hint::black_box(hits);
                        total[usize::from(!new)] += t.elapsed();
                    }
                }
            }
            let n = (reps * rays.len()) as f64;
            println!(
                "{model} {name}: new {:.0} ns, old {:.0} ns, new/old speed {:.3}",
                total[0].as_secs_f64() * 1e9 / n,
                total[1].as_secs_f64() * 1e9 / n,
                total[1].as_secs_f64() / total[0].as_secs_f64()
            );
        }
    }
}
