//! The top level over instances: with many instances they go into a grid of their own, which
//! must find exactly what testing every instance in turn finds, and whose work per ray must
//! grow far slower than the instance count.

#[path = "support/instances/mod.rs"]
mod instances;

use gridtrace::accel::{SceneAccel, TopLevel, TraversalCounts};
use instances::{field, rays};

#[test]
fn the_instance_grid_finds_exactly_what_the_list_finds() {
    for (count, seed) in [(12, 1), (300, 2), (3000, 3)] {
        let scene = field(count, seed);
        let list = SceneAccel::build_with(&scene, TopLevel::List);
        let grid = SceneAccel::build_with(&scene, TopLevel::Grid);
        assert!(grid.instance_grid_resolution().is_some());
        let mut hits = 0;
        for (k, ray) in rays(count, 20_000, seed).iter().enumerate() {
            let expected = list.intersect(ray);
            assert_eq!(
                grid.intersect(ray),
                expected,
                "{count} instances, ray {k}: {ray:?}"
            );
            hits += usize::from(expected.is_some());
            // Shadow segments: of random length, most ending before the first hit.
            let segment = ray.with_t_max(0.5 + 5.0 * (k % 7) as f32);
            assert_eq!(
                grid.occluded(&segment),
                list.occluded(&segment),
                "{count} instances, shadow ray {k}: {segment:?}"
            );
        }
        // Neither almost all misses nor almost all hits: the rays exercise both.
        assert!(
            (4_000..19_000).contains(&hits),
            "{count} instances: {hits} hits"
        );
    }
}

#[test]
fn instance_tests_per_ray_grow_at_most_logarithmically() {
    let tests_per_ray = |count: usize, top_level: TopLevel| {
        let scene = field(count, 5);
        let accel = SceneAccel::build_with(&scene, top_level);
        let rays = rays(count, 20_000, 6);
        let mut counts = TraversalCounts::default();
        for ray in &rays {
            accel.intersect_counting(ray, &mut counts);
        }
        counts.instances as f64 / rays.len() as f64
    };
    let few = tests_per_ray(10, TopLevel::Automatic);
    let many = tests_per_ray(10_000, TopLevel::Automatic);
    let list = tests_per_ray(10_000, TopLevel::List);
    println!("instances considered per ray: {few:.2} of 11, {many:.2} of 10,001 (list: {list:.0})");
    // 1000 times the instances: at most log(10,001)/log(11) ≈ 3.8 times the work.
    let bound = (10_001f64).ln() / 11f64.ln();
    assert!(many <= bound * few, "{many:.2} > {bound:.2} × {few:.2}");
    assert_eq!(list, 10_001.0);
}
