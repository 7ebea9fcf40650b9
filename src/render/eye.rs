//! When a render asks its camera rays of a grid of the camera's eye
//! ([`crate::accel::EyeGrid`]): a speed-up only, since that grid answers exactly as the
//! scene's grids do, so the rule weighs its build time and memory against the camera rays.

use super::{RayGenerator, RenderSettings, Renderer};
use crate::accel::EyeGrid;

/// Camera rays per triangle from which a grid of the eye is built. On the full dragon its
/// build costs what about 14 camera rays per triangle save (docs/design/grid.md, "The grid
/// of the camera's eye"); at 32 it saves about twice its cost.
const RAYS_PER_TRIANGLE: u64 = 32;

/// Triangles below which no grid of the eye is built: a few large triangles share few
/// columns, each holding most of them (the Cornell box's camera rays took 1.4× as long
/// through it; an 11,000-triangle dragon's 0.41×).
const MIN_TRIANGLES: u64 = 10_000;

/// Bytes per triangle a grid of the eye may take while it is built, its working arrays
/// included (the full dragon's render grew by 180 per triangle at its peak).
const BYTES_PER_TRIANGLE: u64 = 256;

/// True when a grid of the eye pays for a render of `camera_rays` camera rays over
/// `triangles` triangles, and fits in half of `memory_left` bytes (it is a speed-up: it
/// must not take the memory a render needs, nor fail one).
fn pays(triangles: u64, camera_rays: u64, memory_left: u64) -> bool {
    triangles >= MIN_TRIANGLES
        && camera_rays >= RAYS_PER_TRIANGLE * triangles
        && BYTES_PER_TRIANGLE * triangles <= memory_left / 2
}

impl Renderer<'_> {
    /// The grid of the camera's eye for a render of `settings`, when it pays ([`pays`]) and
    /// the camera is a still pinhole ([`RayGenerator::pinhole_view`],
    /// [`crate::accel::SceneAccel::eye_grid`]): one column per pixel at most, the window
    /// grown by the filter's width.
    pub fn eye_grid(&self, generator: &RayGenerator, settings: &RenderSettings) -> Option<EyeGrid> {
        let pixels = settings.width as u64 * settings.height as u64;
        let camera_rays = pixels * settings.spp() as u64;
        let triangles = self.accel().triangles() as u64;
        if !pays(triangles, camera_rays, crate::limits::memory_left()) {
            return None;
        }
        let view = generator.pinhole_view(settings.filter_width, pixels.min(1 << 24) as u32)?;
        self.accel().eye_grid(view)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GIB: u64 = 1 << 30;

    #[test]
    fn a_grid_of_the_eye_is_built_for_many_camera_rays_over_many_triangles_within_memory() {
        let dragon = 871_306;
        assert!(pays(dragon, 512 * 512 * 128, 8 * GIB));
        assert!(
            !pays(dragon, 512 * 512 * 64, 8 * GIB),
            "16 rays per triangle"
        );
        assert!(!pays(32, 512 * 512 * 1024, 8 * GIB), "a Cornell box");
        assert!(!pays(dragon, 512 * 512 * 128, 300 << 20), "300 MiB left");
        assert!(pays(dragon, 512 * 512 * 128, 500 << 20), "500 MiB left");
    }
}
