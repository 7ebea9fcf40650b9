//! The grid of the camera's eye answers camera rays exactly as the scene's grids do — the
//! same triangle, `t`, `u` and `v`, bit for bit, on every ray of every dragon and bundled
//! scene — so a render with it is the same image as one without.

#[path = "support/oracles/mod.rs"]
mod oracles;

use glam::Vec3;
use gridtrace::accel::SceneAccel;
use gridtrace::load::load_scene;
use gridtrace::render::{RayGenerator, RenderSettings, Renderer};
use gridtrace::scene::{Camera, Environment, Scene};
use oracles::{DRAGON_MODELS, dragon_path};
use rayon::prelude::*;

/// The scenes: every resolution of the dragon, the bundled Cornell scenes, and Blender
/// exports whose cameras stand inside the scene (a room lit through a window, a room of
/// lamps) or look at glass.
fn scenes() -> Vec<(String, Scene)> {
    let dragons = DRAGON_MODELS.iter().map(|m| dragon_path(m));
    let bundled = [
        "assets/cornell_box.glb",
        "assets/cornell_spheres.glb",
        "tests/data/scenes/window_room.glb",
        "tests/data/scenes/lighting_room_lamps.usdc",
        "tests/data/scenes/principled_glass.glb",
    ]
    .map(Into::into);
    (dragons.chain(bundled))
        .map(|path: std::path::PathBuf| {
            let scene = load_scene(&path).expect("the scene loads").scene;
            (path.display().to_string(), scene)
        })
        .collect()
}

/// The scene's first camera, or the one a model viewer would open it with.
fn camera_of(scene: &Scene) -> Camera {
    (scene.cameras.first().cloned()).unwrap_or_else(|| Camera::framing(&scene.bounds(), 1.0))
}

/// Four camera rays per pixel of a 256 × 256 image, at fixed points in the pixel and at its
/// corners (rays through the window's edge among them): every one the grid of the eye
/// answers, it answers as the scene's grids do, and it answers nearly all.
#[test]
fn camera_rays_find_through_the_eye_what_the_grids_find() {
    let size = 256;
    for (name, scene) in scenes() {
        let accel = SceneAccel::build(&scene);
        let generator = RayGenerator::new(&camera_of(&scene), size, size);
        let view = generator
            .pinhole_view(1.0, size * size)
            .expect("a still pinhole");
        let eye = accel
            .eye_grid(view)
            .expect("the scene lies ahead of the eye");
        let offsets = [(0.5, 0.5), (0.0, 0.0), (0.25, 0.75), (0.9, 0.1)];
        let rays: Vec<_> = (0..size * size)
            .flat_map(|p| offsets.map(|(a, b)| (p, a, b)))
            .map(|(p, a, b)| generator.generate((p % size) as f32 + a, (p / size) as f32 + b))
            .collect();
        let (differing, hits, answered) = rays
            .par_iter()
            .map(|ray| {
                let by_grids = accel.intersect(ray);
                let through_eye = accel.intersect_from(Some(&eye), ray);
                let bits = |h: Option<gridtrace::accel::SceneHit>| {
                    h.map(|h| {
                        (
                            h.t.to_bits(),
                            h.u.to_bits(),
                            h.v.to_bits(),
                            h.triangle,
                            h.instance,
                        )
                    })
                };
                (
                    usize::from(bits(by_grids) != bits(through_eye)),
                    usize::from(by_grids.is_some()),
                    usize::from(eye.answers(ray)),
                )
            })
            .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
        eprintln!(
            "{name}: {} camera rays, {hits} hits, {answered} answered through the eye, {differing} differing",
            rays.len()
        );
        assert!(
            answered > rays.len() * 99 / 100,
            "{name}: {answered} answered through the eye"
        );
        assert_eq!(
            differing, 0,
            "{name}: camera rays answered otherwise through the eye"
        );
        assert!(hits > rays.len() / 20, "{name}: {hits} hits");
    }
}

/// A render that builds the grid of the eye is bit for bit the render that does not.
#[test]
fn a_render_through_the_eye_is_the_same_image() {
    let path = dragon_path(DRAGON_MODELS[3]);
    let mut scene = load_scene(&path).expect("the dragon loads").scene;
    scene.environment = Some(Environment::constant(Vec3::ONE, "a white sky"));
    let renderer = Renderer::new(&scene);
    let camera = camera_of(&scene);
    let settings = |camera_grid| RenderSettings {
        width: 96,
        height: 96,
        samples: 0..48,
        max_depth: 3,
        camera_grid,
        ..RenderSettings::default()
    };
    let generator = RayGenerator::new(&camera, 96, 96);
    assert!(
        renderer.eye_grid(&generator, &settings(true)).is_some(),
        "the render is large enough for a grid of the eye"
    );
    let (with, _) = renderer.render(&camera, &settings(true), &|| {});
    let (without, _) = renderer.render(&camera, &settings(false), &|| {});
    assert!(with.pixels.iter().any(|p| p.max_element() > 0.0));
    assert_eq!(with.pixels, without.pixels);
    assert_eq!(with.alpha, without.alpha);
}
