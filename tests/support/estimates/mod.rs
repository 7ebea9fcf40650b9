//! Monte Carlo estimates of the radiance along one ray, with their standard error, and the
//! check that one matches a closed form.

use glam::DVec3;
use gridtrace::accel::Ray;
use gridtrace::render::sampler::Sampler;
use gridtrace::render::{PathOptions, Renderer, Strategy};
use gridtrace::scene::Scene;

/// Mean radiance along `ray` over `n` paths (the samples of one pixel) and its standard
/// error, per channel.
pub fn estimate(scene: &Scene, ray: Ray, strategy: Strategy, n: u32) -> (DVec3, DVec3) {
    estimate_with(scene, ray, PathOptions::plain(64, strategy), n)
}

/// [`estimate`] with paths traced as `options` ask.
#[allow(dead_code)]
pub fn estimate_with(scene: &Scene, ray: Ray, options: PathOptions, n: u32) -> (DVec3, DVec3) {
    let renderer = Renderer::new(scene);
    let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
    for i in 0..n {
        // The samples of one pixel: stratified, so the spread of the paths over-states the
        // error of their mean, never under-states it.
        let l = renderer
            .trace_path_with(ray, &mut Sampler::for_sample(7, 11, i), options)
            .radiance
            .as_dvec3();
        sum += l;
        sum2 += l * l;
    }
    let mean = sum / n as f64;
    let variance = (sum2 / n as f64 - mean * mean).max(DVec3::ZERO) * (n as f64 / (n as f64 - 1.0));
    (mean, (variance / n as f64).sqrt())
}

/// Asserts that an estimate matches `expected` within 4 standard errors (plus float rounding)
/// and that it is precise enough for that to mean something.
pub fn assert_matches(what: &str, (mean, stderr): (DVec3, DVec3), expected: DVec3, precision: f64) {
    for c in 0..3 {
        let tolerance = 4.0 * stderr[c] + 1e-5 * expected[c];
        assert!(
            (mean[c] - expected[c]).abs() <= tolerance,
            "{what}, channel {c}: {:.6} ± {:.6}, expected {:.6}",
            mean[c],
            stderr[c],
            expected[c]
        );
        assert!(
            stderr[c] <= precision * expected[c],
            "{what}: standard error {} too large to test {}",
            stderr[c],
            expected[c]
        );
    }
}
