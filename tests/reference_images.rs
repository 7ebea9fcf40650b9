//! gridtrace against an independent renderer: each reference scene is rendered by Blender
//! Cycles (`tools/blender/make_references.py`, materials replaced by exactly our models) and
//! by gridtrace, and the two must agree within their measured noise (`image_stats`).

#[path = "support/image_stats/mod.rs"]
mod image_stats;

use gridtrace::load::load_scene;
use gridtrace::render::Renderer;
use image_stats::{SIZE, check_scene, reference, render, scene_path};

#[test]
fn cornell_box_matches_cycles() {
    check_scene("cornell_box", 512);
}

/// Samples per pixel for scenes lit through glass (caustics). Their block means are
/// heavy-tailed: a block's rare bright paths (diffuse → glass → light) are often missed
/// entirely, so it reads low while its measured noise stays small. At 512 spp the max-|z|
/// limit of 5 failed for 4 of 6 seed sets of `cornell_spheres` (up to 12.6, always
/// gridtrace low, in a different block each time) and for 1 of 2 of `caustic`, though the
/// image means agreed to 0.1 %; at 2048 spp 6 of 6 seed sets passed (max |z| 3.2–4.9).
const CAUSTIC_SPP: u32 = 2048;

#[test]
fn cornell_spheres_match_cycles() {
    check_scene("cornell_spheres", CAUSTIC_SPP);
}

#[test]
fn caustic_under_a_glass_sphere_matches_cycles() {
    check_scene("caustic", CAUSTIC_SPP);
}

/// A room lit only through a glazed window: every lit path crosses the pane by a BSDF
/// bounce, so its blocks are heavy-tailed like the caustics'.
#[test]
fn room_lit_through_a_window_matches_cycles() {
    check_scene("window_room", CAUSTIC_SPP);
}

#[test]
fn coloured_and_small_lights_match_cycles() {
    check_scene("coloured_lights", 512);
}

/// The error against the reference falls at least like 1/√spp: an unbiased renderer's mean
/// squared error is its variance, σ²/spp or less (stratified samples converge faster on the
/// smooth parts of the integrand), once the reference's own noise is taken off. A bias
/// would flatten the curve at its square: the last step, 64 → 256 spp, must still fall at
/// least as 1/√spp does, less the slope's noise.
///
/// One 128² image's MSE is itself noisy (±25 % at 8 spp, where rare bright paths are mostly
/// missed), so each level averages renders of the same total work: 64 × 4 spp, 16 × 16 spp,
/// 4 × 64 spp, 1 × 256 spp. That leaves about ±8 % on each MSE, ±0.013 on the fitted slope
/// and ±0.04 on the last step's; measured: −0.72 overall, −0.61 for the last step.
#[test]
fn error_falls_as_one_over_root_spp() {
    let name = "cornell_box";
    let scene = load_scene(&scene_path(name)).unwrap().scene;
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    let reference = reference(name);
    let pixels = SIZE * SIZE;
    let reference_noise: f64 = (0..pixels)
        .map(|i| reference.variance(i).element_sum())
        .sum::<f64>()
        / (3 * pixels) as f64;
    let mut points = Vec::new();
    let mut seed = 10;
    for (spp, renders) in [(4u32, 64u32), (16, 16), (64, 4), (256, 1)] {
        let mut mse = 0.0;
        for _ in 0..renders {
            seed += 1;
            let image = render(&renderer, &camera, spp, seed);
            mse += (0..pixels)
                .map(|i| {
                    let d = image[i] - reference.mean(i);
                    (d * d).element_sum()
                })
                .sum::<f64>()
                / (3 * pixels * renders as usize) as f64;
        }
        let rmse = (mse - reference_noise).max(f64::MIN_POSITIVE).sqrt();
        println!(
            "{spp:>4} spp ({renders} renders): RMSE {rmse:.5} (reference noise {:.5} taken off)",
            reference_noise.sqrt()
        );
        points.push(((spp as f64).ln(), rmse.ln()));
    }
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    let last = (points[3].1 - points[2].1) / (points[3].0 - points[2].0);
    println!("log-log slope {slope:.3}, last step {last:.3}");
    assert!(
        slope < -0.45 && last < -0.45,
        "RMSE against the reference falls with slope {slope:.3} (last step {last:.3}), \
         slower than 1/√spp: {points:?}"
    );
}

/// Blender point, spot and sun lights exported as `KHR_lights_punctual` (Standard units)
/// next to an emissive panel: the balance between them must be Cycles'.
#[test]
fn blender_punctual_lights_match_cycles() {
    check_scene("punctual_lights", 512);
}

/// Blender's export of textures wired the usual ways: a checker through a Mapping node
/// (KHR_texture_transform), a normal map without tangents (MikkTSpace), an emissive texture,
/// an alpha cutout, and a textured box mirrored by a negative scale.
#[test]
fn blender_textures_match_cycles() {
    check_scene("textured", 512);
}
