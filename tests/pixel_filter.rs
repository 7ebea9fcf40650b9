//! Pixel filters against Cycles: the Cornell box rendered by Cycles with its default filter,
//! Blackman–Harris 1.5 px (`tools/blender/make_filter_reference.py`), matches gridtrace's
//! `--filter blackman-harris` within the criteria of every reference, and does so at the
//! edges better than gridtrace's one-pixel box does (the figures are printed).

#[path = "support/image_stats/mod.rs"]
mod image_stats;

use gridtrace::load::load_scene;
use gridtrace::render::{FilterKind, Renderer};
use image_stats::{Halves, SIZE, check_agreement, reference, render_filtered, scene_path};

/// Samples per pixel of gridtrace's side.
const SPP: u32 = 512;

fn halves(filter: FilterKind, width: f32) -> Halves {
    let scene = load_scene(&scene_path("cornell_box")).unwrap().scene;
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    Halves {
        a: render_filtered(&renderer, &camera, SPP / 2, 1, filter, width),
        b: render_filtered(&renderer, &camera, SPP / 2, 2, filter, width),
    }
}

/// Mean squared difference from `theirs` over the pixels where `theirs` has an edge: its
/// central differences sum to more than a tenth of its mean value (pixels at the border
/// skipped). Noise adds the same to both filters' figures; what differs is the filter.
fn edge_error(ours: &Halves, theirs: &Halves) -> (f64, usize) {
    let at = |h: &Halves, x: usize, y: usize| h.mean(y * SIZE + x).element_sum() / 3.0;
    let level = (0..SIZE * SIZE)
        .map(|i| theirs.mean(i).element_sum() / 3.0)
        .sum::<f64>()
        / (SIZE * SIZE) as f64;
    let (mut sum, mut count) = (0.0, 0);
    for y in 1..SIZE - 1 {
        for x in 1..SIZE - 1 {
            let gradient = (at(theirs, x + 1, y) - at(theirs, x - 1, y)).abs()
                + (at(theirs, x, y + 1) - at(theirs, x, y - 1)).abs();
            if gradient > 0.1 * level {
                sum += (at(ours, x, y) - at(theirs, x, y)).powi(2);
                count += 1;
            }
        }
    }
    (sum / count.max(1) as f64, count)
}

#[test]
fn blackman_harris_matches_cycles_default_filter_better_than_a_box() {
    let cycles = reference("cornell_box_blackman_harris");
    let ours = halves(FilterKind::BlackmanHarris, 1.5);
    let boxed = halves(FilterKind::Box, 1.0);
    let ((with_filter, edges), (with_box, _)) =
        (edge_error(&ours, &cycles), edge_error(&boxed, &cycles));
    println!(
        "against Cycles' Blackman-Harris 1.5, mean squared difference over {edges} edge pixels: \
         gridtrace Blackman-Harris {with_filter:.5}, box {with_box:.5} ({:.1}x)",
        with_box / with_filter
    );
    check_agreement(
        "cornell_box, Blackman-Harris 1.5 vs Cycles'",
        &ours,
        &cycles,
    );
    assert!(
        with_box > 1.5 * with_filter,
        "a box agrees about as well at edges: {with_box} vs {with_filter}"
    );
}
