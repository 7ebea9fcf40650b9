//! How much of the view is empty background. A scene lit only by its own emissive
//! surfaces is either an interior those surfaces light (a room, a Cornell box: the camera
//! sees walls everywhere) or an object on nothing whose emitters are details (a product
//! model's headlights, screens or LEDs: the camera sees mostly background). The share of
//! camera rays that reach nothing tells the two apart.

use crate::accel::{SceneAccel, TopLevel};
use crate::scene::{Camera, Scene};

use super::RayGenerator;

/// Rays per side of the grid of pixel-centred camera rays the share is measured with.
const GRID: u32 = 32;

/// The share of a `GRID`×`GRID` grid of pinhole camera rays, over a `width`×`height`
/// image at shutter open, that hit no geometry.
pub fn empty_view_share(scene: &Scene, camera: &Camera, width: u32, height: u32) -> f32 {
    let accel = SceneAccel::build_with(scene, TopLevel::Automatic);
    let generator = RayGenerator::new(camera, width, height);
    let mut empty = 0u32;
    for j in 0..GRID {
        for i in 0..GRID {
            let x = (i as f32 + 0.5) / GRID as f32 * width as f32;
            let y = (j as f32 + 0.5) / GRID as f32 * height as f32;
            if accel.intersect(&generator.generate(x, y)).is_none() {
                empty += 1;
            }
        }
    }
    empty as f32 / (GRID * GRID) as f32
}
