//! Thin-lens depth of field against its closed form: a point at the focus distance stays
//! sharp, and an out-of-focus point spreads into a disc whose radius is the thin-lens circle
//! of confusion, A·|z − s| / (z·s) on the image plane at unit distance (A the aperture
//! radius, s the focus distance, z the point's depth), with its energy kept.

#[path = "support/shapes/mod.rs"]
mod shapes;

use glam::{Affine3A, Vec3};
use gridtrace::render::{RenderSettings, Renderer};
use gridtrace::scene::{Camera, Material, Projection, SceneBuilder, ThinLens};

use shapes::add_quad;

const SIZE: u32 = 64;
const YFOV_DEGREES: f32 = 20.0;

/// The image of a small emissive square (side `side`, facing the camera) at depth `z` on
/// the axis, seen through a lens of radius `radius` focused at `focus`; returns the pixel
/// values' sum and their mean squared distance (pixels²) from the image centre.
fn spot(z: f32, side: f32, radius: f32, focus: f32) -> (f64, f64) {
    let mut b = SceneBuilder::new();
    let m = b.add_material(Material::diffuse("lamp", Vec3::ZERO).with_emission(Vec3::ONE));
    let h = 0.5 * side;
    let v = |x: f32, y: f32| Vec3::new(x, y, -z);
    add_quad(&mut b, [v(-h, -h), v(h, -h), v(h, h), v(-h, h)], m);
    let scene = b.build();
    let camera = Camera {
        name: "lens".into(),
        world_from_camera: Affine3A::IDENTITY,
        projection: Projection::Perspective {
            yfov: YFOV_DEGREES.to_radians(),
            aspect_ratio: None,
        },
        znear: 0.0,
        lens: Some(ThinLens {
            radius,
            focus_distance: focus,
        }),
        focal_length: None,
        shutter: None,
        motion: None,
        source: "test".into(),
    };
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples: 0..4096,
        max_depth: 1,
        ..RenderSettings::default()
    };
    let (image, _) = Renderer::new(&scene).render(&camera, &settings, &|| {});
    let (mut sum, mut moment) = (0.0f64, 0.0f64);
    for (i, p) in image.pixels.iter().enumerate() {
        let (x, y) = (
            (i as u32 % SIZE) as f64 + 0.5,
            (i as u32 / SIZE) as f64 + 0.5,
        );
        let r2 = (x - 0.5 * SIZE as f64).powi(2) + (y - 0.5 * SIZE as f64).powi(2);
        sum += p.x as f64;
        moment += p.x as f64 * r2;
    }
    (sum, moment / sum)
}

/// Pixels per unit of the image plane at unit distance.
fn pixels_per_unit() -> f64 {
    SIZE as f64 / (2.0 * (0.5 * YFOV_DEGREES.to_radians() as f64).tan())
}

#[test]
fn an_out_of_focus_point_spreads_into_its_circle_of_confusion() {
    let (radius, focus, z, side) = (0.4f32, 4.0f32, 2.0f32, 0.04f32);
    let (sum, moment) = spot(z, side, radius, focus);
    // A uniform disc of radius R has mean r² = R²/2; the square's own extent adds q²/6 and
    // the pixel grid 1/6 (a twelfth per axis).
    let coc = (radius * (z - focus).abs() / (z * focus)) as f64 * pixels_per_unit();
    let square = (side / z) as f64 * pixels_per_unit();
    let expected = 0.5 * coc * coc + square * square / 6.0 + 1.0 / 6.0;
    assert!(
        (moment / expected - 1.0).abs() < 0.03,
        "mean r² {moment:.3} px², thin lens says {expected:.3} (circle of confusion {coc:.2} px)"
    );
    // The lens moves the light, it does not lose it: the same square in focus gives the
    // same total, and its pinhole image.
    let (focused_sum, focused_moment) = spot(z, side, radius, z);
    assert!(
        (sum / focused_sum - 1.0).abs() < 0.02,
        "{sum} vs {focused_sum}"
    );
    let sharp = square * square / 6.0 + 1.0 / 6.0;
    assert!(
        (focused_moment / sharp - 1.0).abs() < 0.1,
        "in focus, mean r² {focused_moment:.3} px², the square alone {sharp:.3}"
    );
}

/// On the focus plane, the square's image is its pinhole image (mean r² = q²/6 + 1/6 on the
/// pixel grid) whatever the aperture.
#[test]
fn a_point_on_the_focus_plane_stays_sharp_whatever_the_aperture() {
    let (z, side) = (4.0f32, 0.08f32);
    let square = (side / z) as f64 * pixels_per_unit();
    let sharp = square * square / 6.0 + 1.0 / 6.0;
    for radius in [0.05f32, 0.5, 2.0] {
        let (_, moment) = spot(z, side, radius, z);
        assert!(
            (moment / sharp - 1.0).abs() < 0.1,
            "aperture {radius}: mean r² {moment:.3} px², the square alone {sharp:.3}"
        );
    }
}
