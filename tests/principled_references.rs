//! Blender's Principled BSDF, left as users make it, against Cycles: scenes built and
//! rendered by `tools/blender/make_principled.py`, exported through Blender's glTF and USD
//! exporters, compared with the same criteria as the ideal-material references (image means
//! within 2 %, 8×8 blocks within 5 standard errors, rms z under 1.3).

mod image_stats;

use std::path::Path;

use image_stats::{check_agreement, check_scene, reference, render_halves};

/// Samples per pixel of gridtrace's side.
const SPP: u32 = 512;

fn check_usd(name: &str) {
    let ours = render_halves(
        &Path::new("tests/scenes").join(format!("{name}.usdc")),
        SPP,
        1,
    );
    check_agreement(
        &format!("{name}.usdc at {SPP} spp vs Cycles"),
        &ours,
        &reference(name),
    );
}

/// Gold, steel and copper at roughness 0.2, 0.5 and 0.8 on Blender's default material.
#[test]
fn rough_metals_match_cycles() {
    check_scene("principled_metals", SPP);
}

#[test]
fn rough_metals_from_usd_match_cycles() {
    check_usd("principled_metals");
}

/// Glossy and rough plastics, a clear coat and a sheen.
#[test]
fn plastics_coat_and_sheen_match_cycles() {
    check_scene("principled_plastics", SPP);
}

/// Rough glass, and a metal whose roughness and normal come from textures.
#[test]
fn rough_glass_and_roughness_texture_match_cycles() {
    check_scene("principled_textured", SPP);
}
