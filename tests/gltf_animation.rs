//! glTF animation at a frame against Blender's own evaluation of that frame
//! (`tools/blender/make_gltf_animation.py`): an object animation, a shape-key animation and
//! an armature-skinned tube, exported animated (three animations, one per action), and the
//! same scene exported at frames 1, 7, 13 and 24 with the pose applied by Blender.
//!
//! Limits, fixed before looking: the same triangle count, every vertex within 10⁻⁴ m of
//! one of Blender's (both ways), and at frame 13 renders agreeing within their noise (the
//! reference-image criteria).

#[path = "support/image_stats/mod.rs"]
mod image_stats;
#[path = "support/world/mod.rs"]
mod world;

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::Vec3;
use gridtrace::load::{LoadOptions, load_scene_with};
use gridtrace::scene::Scene;
use image_stats::{check_agreement, render_scene_halves};
use world::{corners, farthest, world_triangles};

const FRAMES: [u32; 4] = [1, 7, 13, 24];

fn scene_file(name: &str) -> PathBuf {
    Path::new("tests/data/scenes/gltf_animation").join(name)
}

fn load_at(path: &Path, frame: Option<f64>, animation: Option<&str>) -> (Scene, Vec<String>) {
    let options = LoadOptions {
        frame,
        animation: animation.map(String::from),
        ..LoadOptions::default()
    };
    let loaded = load_scene_with(path, &options).unwrap_or_else(|e| panic!("{e}"));
    (loaded.scene, loaded.warnings)
}

/// Every triangle corner in world space.
fn world_corners(scene: &Scene) -> Vec<Vec3> {
    corners(&world_triangles(scene))
}

fn posed_error(ours: &Scene, blender: &Scene) -> f32 {
    let (a, b) = (world_corners(ours), world_corners(blender));
    assert_eq!(a.len(), b.len(), "corner count");
    farthest(&a, &b).max(farthest(&b, &a))
}

#[test]
fn every_frame_matches_blenders_evaluation() {
    let animated = scene_file("animated.glb");
    let mut first = None;
    for frame in FRAMES {
        let (ours, warnings) = load_at(&animated, Some(f64::from(frame)), None);
        assert!(warnings.is_empty(), "{warnings:?}");
        let (blender, _) = load_at(&scene_file(&format!("frame_{frame}.glb")), None, None);
        let error = posed_error(&ours, &blender);
        println!("frame {frame}: farthest vertex from Blender's {error:.2e} m");
        assert!(error < 1e-4, "frame {frame}: {error} m");
        let corners = world_corners(&ours);
        let start = first.get_or_insert_with(|| corners.clone());
        if frame == 24 {
            // The animation really moves things: the tube's tip alone travels a metre.
            assert!(farthest(&corners, start) > 0.5);
        }
    }
}

#[test]
fn a_posed_frame_renders_like_blenders() {
    let (ours, _) = load_at(&scene_file("animated.glb"), Some(13.0), None);
    let (blender, _) = load_at(&scene_file("frame_13.glb"), None, None);
    check_agreement(
        "frame 13 posed by gridtrace vs by Blender",
        &render_scene_halves(&ours, 64, 1),
        &render_scene_halves(&blender, 64, 1),
    );
}

#[test]
fn one_animation_can_be_chosen_and_an_unknown_one_is_an_error() {
    let animated = scene_file("animated.glb");
    // Only the armature's action: the cube and the sheet stay as stored.
    let (rig_only, warnings) = load_at(&animated, Some(24.0), Some("RigAction"));
    assert!(warnings.is_empty(), "{warnings:?}");
    let (as_stored, _) = load_at(&animated, None, None);
    let (all, _) = load_at(&animated, Some(24.0), None);
    let cube = |s: &Scene| s.instances[0].world_from_object;
    assert_eq!(cube(&rig_only), cube(&as_stored));
    assert_ne!(cube(&all), cube(&as_stored));
    let options = LoadOptions {
        frame: Some(1.0),
        animation: Some("Walk".into()),
        ..LoadOptions::default()
    };
    let error = load_scene_with(&animated, &options)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("animated.glb") && error.contains("no animation 'Walk'"),
        "{error}"
    );
}

/// glTF-Transform's `sparse` rewrite stores all-zero accessors (here the armature's still
/// translation keys) without a bufferView, the zero-filled form; the pose is the same.
#[test]
fn sparse_rewrites_pose_the_same() {
    let tools = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/dev/npm/node_modules/.bin");
    assert!(
        tools.join("gltf-transform").exists(),
        "glTF-Transform is missing: run tools/dev/setup.sh"
    );
    let dir = tempfile::tempdir().unwrap();
    let sparse = dir.path().join("sparse.glb");
    let out = Command::new(tools.join("gltf-transform"))
        .arg("sparse")
        .arg(scene_file("animated.glb"))
        .arg(&sparse)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&sparse).unwrap();
    let json_length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    let zero_filled = json["accessors"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a.get("bufferView").is_none())
        .count();
    assert!(zero_filled > 0, "the rewrite has no zero-filled accessor");
    for frame in [7.0, 13.0] {
        let (ours, _) = load_at(&sparse, Some(frame), None);
        let (reference, _) = load_at(&scene_file("animated.glb"), Some(frame), None);
        assert_eq!(world_corners(&ours), world_corners(&reference));
    }
}

/// Blender's experimental "Animation Pointer" export writes material animation as
/// `KHR_animation_pointer` channels, which target no node: the file loads, with one warning
/// naming the extension as ignored (the material keeps its stored values), and its node
/// animation plays — the cube's centre at x 0.1 at frame 1 and 2.0 at frame 20.
#[test]
fn animation_pointer_channels_are_ignored_and_node_animation_plays() {
    let path = scene_file("pointer.glb");
    for (frame, x) in [(1.0, 0.1f32), (20.0, 2.0)] {
        let (scene, warnings) = load_at(&path, Some(frame), None);
        assert_eq!(warnings.len(), 1, "{warnings:#?}");
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("pointer.glb") && w.contains("KHR_animation_pointer")),
            "{warnings:#?}"
        );
        let corners = world_corners(&scene);
        let centre = corners.iter().map(|c| c.x).sum::<f32>() / corners.len() as f32;
        assert!(
            (centre - x).abs() < 1e-4,
            "frame {frame}: centre x {centre}"
        );
    }
}
