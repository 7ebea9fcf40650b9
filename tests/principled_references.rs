//! Blender's Principled BSDF, left as users make it, against Cycles: scenes built and
//! rendered by `tools/blender/make_principled.py`, exported through Blender's glTF and USD
//! exporters.
//!
//! Only the image means are checked (within 2 % per channel, as for the ideal-material
//! references): the 8×8-block criteria are not met yet. At 512 spp the blocks measured
//! (README, "How correctness is checked"): metals max |z| 24.9, rms z 2.63 (the gold and
//! steel highlights of the small key light); plastics max |z| 76.9, rms z 7.25 (the sheen
//! sphere: Cycles' Principled sheen is its "microfiber" model, glTF's is Charlie's);
//! textured max |z| 5.9, rms z 1.81. Every test prints its figures.

mod image_stats;

use std::path::Path;

use image_stats::{check_image_means, reference, render_halves, scene_path};

/// Samples per pixel of gridtrace's side.
const SPP: u32 = 512;

fn check(name: &str, path: &Path) {
    let ours = render_halves(path, SPP, 1);
    check_image_means(
        &format!("{} at {SPP} spp vs Cycles", path.display()),
        &ours,
        &reference(name),
    );
}

/// Gold, steel and copper at roughness 0.2, 0.5 and 0.8 on Blender's default material,
/// through both exporters.
#[test]
fn rough_metals_match_cycles_on_average() {
    check("principled_metals", &scene_path("principled_metals"));
    check(
        "principled_metals",
        Path::new("tests/scenes/principled_metals.usdc"),
    );
}

/// Glossy and rough plastics, a clear coat and a sheen.
#[test]
fn plastics_coat_and_sheen_match_cycles_on_average() {
    check("principled_plastics", &scene_path("principled_plastics"));
}

/// Rough glass, and a metal whose roughness and normal come from textures.
#[test]
fn rough_glass_and_roughness_texture_match_cycles_on_average() {
    check("principled_textured", &scene_path("principled_textured"));
}
