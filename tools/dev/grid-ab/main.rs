//! The grid of the working tree (`gridtrace`) against the grid of another commit
//! (`gridtrace_base`), built from the same mesh and timed on the same rays in one process:
//! chunks of 10,000 rays, the two taking each chunk in turn (the order alternating), best of
//! 7 per chunk, the rounds' ratios sorted. One process removes the machine's drift between
//! runs, which on the development machine moves separate runs by up to a tenth; the same
//! code against itself gives 1.005 ± 0.015. Built and run by `tools/dev/grid-ab.sh`, not part
//! of the crate.

mod rays;

use std::time::Instant;

use gridtrace::accel::{Grid, Ray, Triangle};
use gridtrace::geometry::Aabb;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map_or("dragon_vrip.ply.gz", String::as_str);
    let sets = args
        .get(2)
        .map_or("outside,camera,bounce,shadow", String::as_str);
    let rounds: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let count: usize = std::env::var("GRID_AB_RAYS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(50_000);
    // GRID_AB_CHUNK: rays per chunk. Chunks of a few hundred rays, each traced 7 times,
    // stay in cache after the first time, so their best time is what a query costs where
    // memory is fast (its computation alone, as the benchmark's warm figure).
    let chunk: usize = std::env::var("GRID_AB_CHUNK")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let data = std::env::var("GRID_AB_DATA").expect("set by tools/dev/grid-ab.sh");
    let path = std::path::Path::new(&data).join(model);
    let (positions, indices) = gridtrace::load::ply::read_mesh(&path).expect("a readable mesh");
    // GRID_AB_DENSITY: this tree's grid at that many cells per triangle instead of the
    // density it chooses (to try a density against the commit's choice).
    let density = std::env::var("GRID_AB_DENSITY").ok().map(|s| {
        s.parse::<f32>()
            .expect("GRID_AB_DENSITY is a number of cells per triangle")
    });
    let new = match density {
        Some(d) => Grid::from_mesh_with_density(positions.clone(), &indices, d),
        None => Grid::from_mesh(positions.clone(), &indices),
    };
    let base = gridtrace_base::accel::Grid::from_mesh(positions.clone(), &indices);
    println!(
        "{model}: {:?} cells; bytes this tree {}, base {}",
        new.stats().resolution,
        new.stats().bytes,
        base.stats().bytes
    );
    let triangles: Vec<Triangle> = indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            Triangle::new(a, b, c)
        })
        .collect();
    let bounds = Aabb::from_points(positions.iter().copied());
    for set in sets.split(',') {
        let rays: Vec<Ray> = match set {
            "outside" => rays::outside_rays(&bounds, count, 21),
            "camera" => rays::camera_rays(&bounds, count),
            "bounce" => rays::bounce_rays(&triangles, count, 22),
            "shadow" => rays::segments(
                &rays::bounce_rays(&triangles, count, 22),
                0.3 * bounds.extent().length(),
                23,
            ),
            "light" => rays::light_segments(&triangles, &bounds, count, 24),
            // Pairs: a camera ray, then the light segment from its hit.
            "seen" => rays::seen_light_pairs(&triangles, &bounds, count / 2, 25, |r| {
                base.intersect(&gridtrace_base::accel::Ray::new(r.origin, r.direction))
                    .map(|h| (h.t, h.u, h.v, h.triangle))
            }),
            other => {
                panic!("unknown ray set {other}: outside, camera, bounce, shadow, light or seen")
            }
        };
        let base_rays: Vec<gridtrace_base::accel::Ray> = rays
            .iter()
            .map(|r| {
                let mut b = gridtrace_base::accel::Ray::new(r.origin, r.direction);
                (b.t_min, b.t_max, b.time) = (r.t_min, r.t_max, r.time);
                b
            })
            .collect();
        // Shadow queries; for `seen`, every second ray (each after the camera ray whose hit
        // it starts from, traced in that order).
        let shadow = |i: usize| match set {
            "shadow" | "light" => true,
            "seen" => i % 2 == 1,
            _ => false,
        };
        let trace_new = |chunk: &[Ray]| {
            chunk
                .iter()
                .enumerate()
                .filter(|(i, r)| {
                    if shadow(*i) {
                        new.occluded(r)
                    } else {
                        new.intersect(r).is_some()
                    }
                })
                .count()
        };
        let trace_base = |chunk: &[gridtrace_base::accel::Ray]| {
            chunk
                .iter()
                .enumerate()
                .filter(|(i, r)| {
                    if shadow(*i) {
                        base.occluded(r)
                    } else {
                        base.intersect(r).is_some()
                    }
                })
                .count()
        };
        let differ = rays
            .iter()
            .zip(&base_rays)
            .enumerate()
            .filter(|(i, (r, b))| {
                if shadow(*i) {
                    new.occluded(r) != base.occluded(b)
                } else {
                    new.intersect(r).map(|h| (h.t, h.triangle))
                        != base.intersect(b).map(|h| (h.t, h.triangle))
                }
            })
            .count();
        let best_of_7 = |run: &dyn Fn() -> usize| {
            (0..7)
                .map(|_| {
                    let start = Instant::now();
                    std::hint::black_box(run());
                    start.elapsed().as_secs_f64()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let mut ratios: Vec<f64> = (0..rounds)
            .map(|round| {
                let (mut t_new, mut t_base) = (0.0, 0.0);
                for (c, (a, b)) in rays
                    .chunks(chunk)
                    .zip(base_rays.chunks(chunk))
                    .enumerate()
                {
                    for turn in 0..2 {
                        if (turn + c + round) % 2 == 0 {
                            t_new += best_of_7(&|| trace_new(a));
                        } else {
                            t_base += best_of_7(&|| trace_base(b));
                        }
                    }
                }
                t_new / t_base
            })
            .collect();
        ratios.sort_by(f64::total_cmp);
        println!(
            "{set}: {differ} of {} answers differ; time this tree / base: median {:.3}, range {:.3}–{:.3}",
            rays.len(),
            ratios[rounds / 2],
            ratios[0],
            ratios[rounds - 1]
        );
    }
}
