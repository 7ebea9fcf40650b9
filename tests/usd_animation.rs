//! USD animation: time-sampled transforms, points, cameras and lights read at `--frame`,
//! on a hand-written stage and on Blender's animation export.

#[path = "support/world/mod.rs"]
mod world;

use std::path::Path;

use glam::Vec3;
use gridtrace::load::{LoadOptions, load_scene_with};
use gridtrace::scene::{LightKind, Projection, Scene};
use world::{close, source_triangles as world_triangles};

/// The scene at `frame` (`None`: the stage's start), which must load without warnings.
fn scene_at_frame(path: &Path, frame: Option<f64>) -> Scene {
    let options = LoadOptions {
        frame,
        ..LoadOptions::default()
    };
    let loaded = load_scene_with(path, &options).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    loaded.scene
}

/// An animated stage, as Blender writes one: time-sampled transform, points, camera and
/// light. Each is read at the frame asked for (linearly interpolated between samples), or
/// at `startTimeCode` by default; attributes without samples keep their default.
const ANIMATED: &str = r#"#usda 1.0
(
    upAxis = "Y"
    metersPerUnit = 1
    startTimeCode = 1
    endTimeCode = 11
)
def Xform "Mover"
{
    double3 xformOp:translate.timeSamples = {
        1: (0, 0, 0),
        11: (10, 0, 0),
    }
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def Mesh "Tri"
    {
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points.timeSamples = {
            1: [(0, 0, 0), (1, 0, 0), (0, 1, 0)],
            11: [(0, 0, 0), (1, 0, 0), (0, 3, 0)],
        }
    }
}
def Camera "Cam"
{
    float focalLength.timeSamples = {
        1: 50,
        11: 25,
    }
    float horizontalAperture = 24
    float verticalAperture = 24
    double3 xformOp:translate = (0, 0, 10)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
def SphereLight "Lamp"
{
    float inputs:intensity.timeSamples = {
        1: 100.0,
        11: 300.0,
    }
    float inputs:radius = 0.1
    bool treatAsPoint = 1
}
"#;

#[test]
fn animated_stages_are_read_at_the_frame_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("animated.usda");
    std::fs::write(&path, ANIMATED).unwrap();
    let at = |frame| scene_at_frame(&path, frame);
    let apex = |scene: &Scene| world_triangles(scene, "/Mover/Tri")[0][2];
    let fov = |scene: &Scene| match scene.cameras[0].projection {
        Projection::Perspective { yfov, .. } => yfov,
        ref other => panic!("{other:?}"),
    };
    let intensity = |scene: &Scene| match scene.lights[0].kind {
        LightKind::Point { intensity, .. } => intensity.x,
        ref other => panic!("{other:?}"),
    };

    let start = at(None);
    assert!(
        close(apex(&start), Vec3::new(0.0, 1.0, 0.0)),
        "{}",
        apex(&start)
    );
    let first = at(Some(1.0));
    assert_eq!(apex(&first), apex(&start));
    assert_eq!(fov(&first), fov(&start));

    // Halfway: the transform and the points are interpolated.
    let middle = at(Some(6.0));
    assert!(
        close(apex(&middle), Vec3::new(5.0, 2.0, 0.0)),
        "{}",
        apex(&middle)
    );
    // The last sample holds after the end.
    let after = at(Some(20.0));
    assert!(
        close(apex(&after), Vec3::new(10.0, 3.0, 0.0)),
        "{}",
        apex(&after)
    );
    // Camera and light follow their samples too: half the focal length widens the view;
    // three times the intensity triples the light.
    let last = at(Some(11.0));
    assert!(
        fov(&last) > fov(&start) * 1.5,
        "{} vs {}",
        fov(&last),
        fov(&start)
    );
    let ratio = intensity(&last) / intensity(&start);
    assert!((ratio - 3.0).abs() < 1e-4, "{ratio}");
    let ratio = intensity(&middle) / intensity(&start);
    assert!((ratio - 2.0).abs() < 1e-4, "interpolated: {ratio}");
}

/// Blender's own animation export (tools/blender/make_animated.py): a cube sliding 2 m, a
/// camera zooming from 50 to 25 mm, a point light going from 100 to 300 W, one time
/// sample per frame over 1–11. Read at the first, middle and last frame.
#[test]
fn blender_animation_is_read_at_each_frame() {
    let path = Path::new("tests/data/scenes/animated.usdc");
    let at = |frame| scene_at_frame(path, frame);
    let cube_centre = |scene: &Scene| {
        let inst = scene
            .instances
            .iter()
            .find(|i| i.source.contains("Mover"))
            .expect("the cube");
        let mesh = &scene.meshes[inst.mesh];
        let sum: Vec3 = mesh
            .positions
            .iter()
            .map(|p| inst.world_from_object.transform_point3(*p))
            .sum();
        sum / mesh.positions.len() as f32
    };
    let yfov_degrees = |scene: &Scene| match scene.cameras[0].projection {
        Projection::Perspective { yfov, .. } => yfov.to_degrees(),
        ref other => panic!("{other:?}"),
    };
    let watts = |scene: &Scene| match scene.lights[0].kind {
        // Blender's point light of P watts is an intensity of P/(4π) W/sr.
        LightKind::Point { intensity, .. } => intensity.x * 4.0 * std::f32::consts::PI,
        ref other => panic!("{other:?}"),
    };
    // Vertical field of view of a 24 mm sensor: 2·atan(12 / focal length).
    let fov = |focal: f32| (2.0 * (12.0 / focal).atan()).to_degrees();
    for (frame, x, focal, power) in [
        (None, 0.0, 50.0, 100.0),
        (Some(1.0), 0.0, 50.0, 100.0),
        (Some(6.0), 1.0, 37.5, 200.0),
        (Some(11.0), 2.0, 25.0, 300.0),
    ] {
        let scene = at(frame);
        let centre = cube_centre(&scene);
        assert!(
            (centre - Vec3::new(x, 0.25, 0.0)).abs().max_element() < 1e-4,
            "{frame:?}: {centre}"
        );
        assert!(
            (yfov_degrees(&scene) - fov(focal)).abs() < 0.01,
            "{frame:?}: {}° for {focal} mm",
            yfov_degrees(&scene)
        );
        assert!(
            (watts(&scene) / power - 1.0).abs() < 1e-4,
            "{frame:?}: {} W",
            watts(&scene)
        );
    }
}
