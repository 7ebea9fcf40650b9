//! Throwaway driver: grid vs irregular grid vs Embree.
#[path = "../tests/oracles/mod.rs"]
#[allow(dead_code)]
mod oracles;
use gridtrace::accel::grid::{IrregularGrid, IrregularParams};
use gridtrace::accel::{Grid, Ray, TraversalCounts};
use gridtrace::load::ply;
use gridtrace::scene::Aabb;
use oracles::embree::Embree;
use oracles::rays::{bounce_rays, outside_rays};
use oracles::{Mesh, dragon_path};
use std::time::Instant;

fn env<T: std::str::FromStr>(k: &str, d: T) -> T {
    std::env::var(k).ok().and_then(|s| s.parse().ok()).unwrap_or(d)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map(String::as_str).unwrap_or("dragon_vrip.ply.gz");
    let sets = args.get(2).map(String::as_str).unwrap_or("outside,bounce");
    let rounds: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3);
    let count: usize = env("RAYS", 50_000);
    let (positions, indices) = ply::read_mesh(&dragon_path(model)).unwrap();
    let mesh = Mesh { positions, indices };
    let triangles = mesh.triangles();
    let grid = Grid::from_mesh_with_density(mesh.positions.clone(), &mesh.indices, env("DENSITY", 5.0));
    let t = Instant::now();
    let params = IrregularParams { step_cost: env("CT", 1.0), expand_limit: env("EXPAND", 64), merge: env("MERGE", 1) == 1 };
    let irr = IrregularGrid::from_grid(&grid, params);
    let gs = grid.stats();
    let is = irr.stats();
    eprintln!("irregular build {:.3}s; grid {:?} cells {} refs {} bytes/tri {:.1}; irr cells {} (empty {}) blocks {} refs {} bytes/tri {:.1}",
        t.elapsed().as_secs_f64(), gs.resolution, gs.cells, gs.references, gs.bytes as f64 / gs.triangles as f64,
        is.cells, is.empty_cells, is.blocks, is.references, is.bytes as f64 / gs.triangles as f64);
    let embree = Embree::build(&mesh);
    let bounds = Aabb::from_points(mesh.positions.iter().copied());
    for set in sets.split(',') {
        let rays: Vec<Ray> = match set {
            "outside" => outside_rays(&bounds, count, 21),
            _ => bounce_rays(&triangles, count, 22),
        };
        // agreement
        let mut steps = 0u64;
        let mut differ = 0;
        for r in &rays {
            let a = grid.intersect(r);
            let b = irr.intersect(r, &mut steps);
            if a.map(|h| (h.triangle, h.t)) != b.map(|h| (h.triangle, h.t)) {
                differ += 1;
                if differ <= 3 {
                    eprintln!("differ: grid {:?} irr {:?}", a, b);
                }
            }
        }
        let mut counts = TraversalCounts::default();
        for r in &rays {
            grid.intersect_counting(r, &mut counts);
        }
        let n = rays.len() as f64;
        eprintln!("{set}: differ {differ}; irr steps {:.2}; grid cells {:.2} occ {:.2} tests {:.1}",
            steps as f64 / n, counts.cells as f64 / n, counts.occupied as f64 / n, counts.tests as f64 / n);
        let stops: Vec<f32> = rays.iter().map(|r| irr.intersect(r, &mut 0).map_or(f32::INFINITY, |h| h.t)).collect();
        let mut ws = 0u64;
        for (r, &t) in rays.iter().zip(&stops) { irr.walk(r, &mut ws, t); }
        eprintln!("walk: steps {:.2} occupied {:.2}", (ws % 1000) as f64 / n, (ws / 1000) as f64 / n);
        for _ in 0..2 {
            let t = Instant::now();
            let mut s = 0u64;
            for (r, &ts) in rays.iter().zip(&stops) { std::hint::black_box(irr.walk(r, &mut s, ts)); }
            let tw = t.elapsed().as_secs_f64();
            let t = Instant::now();
            for r in &rays { std::hint::black_box(irr.intersect(r, &mut s)); }
            let ti = t.elapsed().as_secs_f64();
            let t = Instant::now();
            for (r, &ts) in rays.iter().zip(&stops) { std::hint::black_box(grid.walk(r, ts)); }
            let tgw = t.elapsed().as_secs_f64();
            let t = Instant::now();
            for r in &rays { std::hint::black_box(grid.intersect(r)); }
            let tg = t.elapsed().as_secs_f64();
            eprintln!("ns/ray: irr walk {:.0} full {:.0}; grid walk {:.0} full {:.0}", tw*1e9/n, ti*1e9/n, tgw*1e9/n, tg*1e9/n);
        }
        let mut rg = vec![];
        let mut ri = vec![];
        for round in 0..rounds {
            let mut tt = [0.0f64; 3];
            for (c, chunk) in rays.chunks(10_000).enumerate() {
                for k in 0..3 {
                    let q = (k + c + round) % 3;
                    let best = (0..7)
                        .map(|_| {
                            let t = Instant::now();
                            let mut s = 0u64;
                            let h = match q {
                                0 => chunk.iter().filter(|r| grid.intersect(r).is_some()).count(),
                                1 => chunk.iter().filter(|r| irr.intersect(r, &mut s).is_some()).count(),
                                _ => chunk.iter().filter(|r| embree.intersect(r).is_some()).count(),
                            };
                            std::hint::black_box((h, s));
                            t.elapsed().as_secs_f64()
                        })
                        .fold(f64::INFINITY, f64::min);
                    tt[q] += best;
                }
            }
            rg.push(tt[2] / tt[0]);
            ri.push(tt[2] / tt[1]);
            println!("{set} round {round}: ns/ray grid {:.0} irr {:.0} embree {:.0}; grid/E {:.3} irr/E {:.3}",
                tt[0] * 1e9 / n, tt[1] * 1e9 / n, tt[2] * 1e9 / n, tt[2] / tt[0], tt[2] / tt[1]);
        }
        rg.sort_by(f64::total_cmp);
        ri.sort_by(f64::total_cmp);
        println!("{set}: median grid/E {:.3} irr/E {:.3}", rg[rounds / 2], ri[rounds / 2]);
    }
}
