//! One structure's queries on one ray set, for a processor simulator to count: the grid or
//! Embree 4 over a dragon, the rays traced once to settle the caches and then once more in
//! [`counted_pass`], the function `tools/dev/accel-counters.sh` tells callgrind to count in
//! (instructions, simulated cache misses and mispredicted branches). This machine's
//! processor exposes no counters of its own (`perf stat`: cycles not supported), so these
//! simulated ones are where a query's work is counted; the times stay `benches/accel.rs`'s.
//!
//! Not a timing: run under `tools/dev/accel-counters.sh`. Environment: `COUNTERS_MODEL` (a file
//! of data/dragon, default the full dragon), `COUNTERS_STRUCTURE` (`grid` or `embree`),
//! `COUNTERS_SET` (`outside`, `camera`, `bounce`, `shadow` or `light`), `COUNTERS_RAYS` (default
//! 10,000).

#[path = "../tests/support/oracles/mod.rs"]
mod oracles;

use std::hint::black_box;

use gridtrace::accel::{Grid, Ray};
use gridtrace::geometry::Aabb;
use gridtrace::load::ply;
use oracles::embree::Embree;
use oracles::rays::{bounce_rays, camera_rays, light_segments, outside_rays, segments};
use oracles::{Mesh, dragon_path};

type Query<'a> = &'a dyn Fn(&Ray) -> bool;

/// Traces every ray; the number that hit (or are blocked). Not inlined, so that the
/// simulator can count exactly the work done in it.
#[inline(never)]
fn counted_pass(rays: &[Ray], query: Query) -> usize {
    rays.iter().filter(|r| query(black_box(r))).count()
}

/// The pass before, which is not counted: it brings what the rays read into the caches as
/// far as they hold it, as the benchmark's repeats of a chunk do.
#[inline(never)]
fn settling_pass(rays: &[Ray], query: Query) -> usize {
    rays.iter().filter(|r| query(black_box(r))).count()
}

/// A structure's shadow query (`occlusion`) or its closest-hit query, as one function.
fn query_of<'a>(
    occlusion: bool,
    intersect: impl Fn(&Ray) -> bool + 'a,
    occluded: impl Fn(&Ray) -> bool + 'a,
) -> Box<dyn Fn(&Ray) -> bool + 'a> {
    if occlusion {
        Box::new(occluded)
    } else {
        Box::new(intersect)
    }
}

fn env_or(name: &str, default: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| default.to_string())
}

fn main() {
    let model = env_or("COUNTERS_MODEL", "dragon_vrip.ply.gz");
    let structure = env_or("COUNTERS_STRUCTURE", "grid");
    let set = env_or("COUNTERS_SET", "outside");
    let count: usize = env_or("COUNTERS_RAYS", "10000")
        .parse()
        .expect("COUNTERS_RAYS is a number of rays");
    let (positions, indices) = ply::read_mesh(&dragon_path(&model)).expect("read the dragon");
    let mesh = Mesh { positions, indices };
    let bounds = Aabb::from_points(mesh.positions.iter().copied());
    // The same sets and seeds as benches/accel.rs.
    let (rays, occlusion) = match set.as_str() {
        "outside" => (outside_rays(&bounds, count, 21), false),
        "camera" => (camera_rays(&bounds, count), false),
        "bounce" => (bounce_rays(&mesh.triangles(), count, 22), false),
        "shadow" => {
            let bounce = bounce_rays(&mesh.triangles(), count, 22);
            (segments(&bounce, 0.3 * bounds.extent().length(), 23), true)
        }
        "light" => (light_segments(&mesh.triangles(), &bounds, count, 24), true),
        other => panic!("COUNTERS_SET {other:?}: one of outside, camera, bounce, shadow, light"),
    };
    // Built in the arm that needs it, borrowed by the query.
    let (grid, embree);
    let query = match structure.as_str() {
        "grid" => {
            grid = Grid::from_mesh(mesh.positions.clone(), &mesh.indices);
            query_of(
                occlusion,
                |r| grid.intersect(r).is_some(),
                |r| grid.occluded(r),
            )
        }
        "embree" => {
            embree = Embree::build(&mesh);
            query_of(
                occlusion,
                |r| embree.intersect(r).is_some(),
                |r| embree.occluded(r),
            )
        }
        other => panic!("COUNTERS_STRUCTURE {other:?}: grid or embree"),
    };
    settling_pass(&rays, &*query);
    let hits = counted_pass(&rays, &*query);
    println!(
        "{model} {structure} {set}: {} rays, {hits} hits",
        rays.len()
    );
}
