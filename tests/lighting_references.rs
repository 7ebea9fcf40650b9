//! Light as Blender users set it, against Cycles: scenes built and rendered by
//! `tools/blender/make_lighting.py` — an HDR world (as a USD `DomeLight`, and as glTF with
//! the same .hdr given as gridtrace's environment), a sun under a sky-coloured world, and
//! Blender's area and point lamps with a size, which the camera does not see. Compared with
//! the criteria of the other references (image means within 2 %, 8×8 blocks within 5
//! standard errors, rms z under 1.3).

#[path = "support/image_stats/mod.rs"]
mod image_stats;

use std::path::Path;

use glam::Vec3;
use gridtrace::load::{load_environment, load_scene};
use gridtrace::scene::{Environment, Scene};
use image_stats::{check_agreement, reference, render_scene_halves};

/// Samples per pixel of gridtrace's side.
const SPP: u32 = 1024;

/// The sky colour of the sun-and-sky world (make_lighting.py's `SKY_COLOUR`).
const SKY: Vec3 = Vec3::new(0.3, 0.45, 0.7);

fn scene(file: &str) -> Scene {
    let loaded = load_scene(&Path::new("tests/data/scenes").join(file)).unwrap();
    assert!(loaded.warnings.is_empty(), "{file}: {:?}", loaded.warnings);
    loaded.scene
}

fn check(name: &str, what: &str, scene: &Scene) {
    let ours = render_scene_halves(scene, SPP, 1);
    check_agreement(
        &format!("{what} at {SPP} spp vs Cycles"),
        &ours,
        &reference(name),
    );
}

/// Blender's world as an Environment Texture: the USD export's dome light reads the .hdr.
#[test]
fn hdr_world_from_usd_matches_cycles() {
    let scene = scene("lighting_hdr.usdc");
    let map = scene.environment.as_ref().and_then(|e| e.map.as_ref());
    assert!(
        map.is_some_and(|m| m.width == 128 && m.height == 64),
        "the dome's map"
    );
    check("lighting_hdr", "lighting_hdr.usdc", &scene);
}

/// The glTF export has no world; `--environment` on the same .hdr gives it back.
#[test]
fn hdr_world_given_to_gltf_matches_cycles() {
    let mut scene = scene("lighting_hdr.glb");
    let sky = load_environment(Path::new("tests/data/scenes/textures/lighting_sky.hdr")).unwrap();
    scene.environment = Some(sky);
    check("lighting_hdr", "lighting_hdr.glb + --environment", &scene);
}

/// A sun lamp and a constant world: USD writes a DistantLight and a one-colour dome map.
#[test]
fn sun_and_sky_from_usd_match_cycles() {
    check(
        "lighting_sun_sky",
        "lighting_sun_sky.usdc",
        &scene("lighting_sun_sky.usdc"),
    );
}

/// The glTF export keeps the sun (KHR_lights_punctual); the sky is `--environment R,G,B`.
#[test]
fn sun_from_gltf_and_a_constant_sky_match_cycles() {
    let mut scene = scene("lighting_sun_sky.glb");
    assert_eq!(scene.lights.len(), 1, "the sun");
    scene.environment = Some(Environment::constant(SKY, "--environment"));
    check(
        "lighting_sun_sky",
        "lighting_sun_sky.glb + --environment",
        &scene,
    );
}

/// A square area lamp and a point lamp of radius 0.25 m, both in view: their light and
/// soft shadows match, and the camera sees neither, as in Cycles.
#[test]
fn area_and_sphere_lamps_from_usd_match_cycles() {
    let scene = scene("lighting_lamps.usdc");
    assert!(
        scene
            .materials
            .iter()
            .any(|m| m.is_emissive() && !m.camera_visible)
    );
    check("lighting_lamps", "lighting_lamps.usdc", &scene);
}

/// Blender's camera depth of field (f/0.4, focused on the grey sphere), as its USD exporter
/// writes it (fStop, focusDistance, focalLength), through gridtrace's thin lens. Held to
/// the block test since the model tolerance covers near-noiseless blocks (before it, one
/// sky block at the blurred horizon read |z| 5.16 from a 10⁻⁴ relative difference).
#[test]
fn depth_of_field_from_usd_matches_cycles() {
    let scene = scene("lighting_dof.usdc");
    assert!(scene.cameras[0].lens.is_some(), "the camera's lens");
    check("lighting_dof", "lighting_dof.usdc", &scene);
}

/// A room lit by a ceiling area lamp 5 cm under the ceiling and Blender's default point
/// lamp (radius 0.1 m, Soft Falloff) low over the floor: the lamp is not geometry, so the
/// ceiling above it is lit by the floor's light passing it, and the floor near the point
/// lamp falls off as Cycles' disc does.
#[test]
fn ceiling_area_lamp_and_soft_falloff_lamp_from_usd_match_cycles() {
    let scene = scene("lighting_room_lamps.usdc");
    check("lighting_room_lamps", "lighting_room_lamps.usdc", &scene);
}
