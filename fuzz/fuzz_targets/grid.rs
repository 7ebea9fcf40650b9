//! Grid construction from arbitrary triangles (any floats, NaN and infinities included),
//! then the structure's invariants and a few queries.
#![no_main]

use glam::Vec3;
use gridtrace::accel::{Grid, Ray, Triangle};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let floats: Vec<f32> = data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    let triangles: Vec<Triangle> = floats
        .chunks_exact(9)
        .take(2000)
        .map(|f| Triangle::new(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]), Vec3::new(f[6], f[7], f[8])))
        .collect();
    let grid = Grid::build(triangles.clone());
    grid.validate().expect("grid invariants");
    let b = grid.bounds();
    for (i, tri) in triangles.iter().enumerate().take(16) {
        let origin = b.max + Vec3::splat(1.0) + Vec3::new(i as f32, 0.5, 0.25);
        let ray = Ray::new(origin, tri.v0 + 0.3 * tri.e1 + 0.3 * tri.e2 - origin);
        let hit = grid.intersect(&ray);
        assert_eq!(hit.is_some(), grid.occluded(&ray), "closest and any-hit disagree");
    }
});
