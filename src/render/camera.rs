//! Turning a scene camera and an image size into primary rays.

use glam::{Affine3A, Vec2, Vec3};

use super::sampling::concentric_disk;
use crate::accel::{Ray, View};
use crate::scene::{Camera, Motion, Projection, ThinLens};

/// Generates the ray through a point of the image plane.
#[derive(Clone, Debug)]
pub struct RayGenerator {
    world_from_camera: Affine3A,
    /// `world_from_camera` over the shutter, when the camera moves.
    motion: Option<Motion>,
    projection: Projection,
    /// Half-extent of the image plane at distance 1 (perspective) or in scene units
    /// (orthographic), horizontally and vertically.
    half_extent: Vec2,
    znear: f32,
    lens: Option<ThinLens>,
    width: u32,
    height: u32,
}

impl RayGenerator {
    /// Rays for a `width`×`height` image. The vertical field of view (or `ymag`) is kept and
    /// the horizontal one follows the image's aspect ratio.
    pub fn new(camera: &Camera, width: u32, height: u32) -> RayGenerator {
        let aspect = width as f32 / height as f32;
        let half_extent = match camera.projection {
            Projection::Perspective { yfov, .. } => {
                let h = (0.5 * yfov).tan();
                Vec2::new(h * aspect, h)
            }
            Projection::Orthographic { ymag, .. } => Vec2::new(ymag * aspect, ymag),
        };
        RayGenerator {
            world_from_camera: camera.world_from_camera,
            motion: camera.motion.clone(),
            projection: camera.projection,
            half_extent,
            znear: camera.znear.max(0.0),
            lens: match camera.projection {
                Projection::Perspective { .. } => camera.lens.filter(|l| l.radius > 0.0),
                Projection::Orthographic { .. } => None,
            },
            width,
            height,
        }
    }

    /// The ray through image position (`x`, `y`) in pixels, (0, 0) at the top-left corner.
    ///
    /// The direction is not normalised: its camera-space z is −1, so `t_min = znear` clips
    /// exactly at the near plane.
    pub fn generate(&self, x: f32, y: f32) -> Ray {
        self.generate_through_lens(x, y, Vec2::splat(0.5), 0.0)
    }

    /// World space to camera space at shutter time 0, the frame [`RayGenerator::generate`]
    /// uses.
    pub fn camera_from_world(&self) -> Affine3A {
        self.motion
            .as_ref()
            .map_or(self.world_from_camera, |m| m.at(0.0))
            .inverse()
    }

    /// Distance in front of the camera (camera-space −z) below which nothing is seen.
    pub fn near(&self) -> f32 {
        self.znear
    }

    /// Where pinhole rays meet camera-space point `p` (in front of the near plane): its
    /// position in the image, in pixels from the top-left corner, as `generate` takes it.
    pub fn image_position(&self, p: Vec3) -> Vec2 {
        let plane = match self.projection {
            Projection::Perspective { .. } => p.truncate() / -p.z,
            Projection::Orthographic { .. } => p.truncate(),
        };
        let ndc = plane / self.half_extent;
        Vec2::new(
            (ndc.x + 1.0) * 0.5 * self.width as f32,
            (1.0 - ndc.y) * 0.5 * self.height as f32,
        )
    }

    /// What a grid of the eye ([`View`]) needs of a still pinhole camera: its eye, its frame
    /// in the world, and the window of the plane one unit ahead that the image, grown by
    /// `margin` pixels on every side, covers; `None` for a lens, an orthographic or a moving
    /// camera, or a frame whose axes are not at right angles.
    pub fn pinhole_view(&self, margin: f32, max_columns: u32) -> Option<View> {
        if self.lens.is_some()
            || self.motion.is_some()
            || !matches!(self.projection, Projection::Perspective { .. })
        {
            return None;
        }
        let m = &self.world_from_camera;
        let axes = [Vec3::X, Vec3::Y, Vec3::NEG_Z].map(|a| m.transform_vector3(a));
        let [right, up, forward] = axes.map(Vec3::normalize_or_zero);
        let square = |a: Vec3, b: Vec3| a.dot(b).abs() < 1e-6;
        if !(square(right, up) && square(up, forward) && square(forward, right))
            || [right, up, forward].contains(&Vec3::ZERO)
        {
            return None;
        }
        // A direction (x, y, −1) in the camera meets the plane at (x, y) scaled by the axes'
        // lengths.
        let scale = Vec2::new(axes[0].length(), axes[1].length()) / axes[2].length();
        let per_pixel = 2.0 * self.half_extent / Vec2::new(self.width as f32, self.height as f32);
        let half = (self.half_extent + margin * per_pixel) * scale;
        Some(View {
            // As the rays are made, so that their origins equal it.
            eye: m.transform_point3(Vec3::ZERO),
            right,
            up,
            forward,
            lo: -half,
            hi: half,
            max_columns,
        })
    }

    /// True when rays leave a lens of some size: each sample then needs a lens position.
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// [`RayGenerator::generate`] from the point of the lens that uniforms `u` pick (the
    /// concentric map onto the aperture disc); the centre, (½, ½), is the pinhole's ray.
    /// The direction keeps camera-space z = −1. `time` is the sample's shutter time.
    pub fn generate_through_lens(&self, x: f32, y: f32, u: Vec2, time: f32) -> Ray {
        let ndc = Vec2::new(
            2.0 * x / self.width as f32 - 1.0,
            1.0 - 2.0 * y / self.height as f32,
        );
        let plane = ndc * self.half_extent;
        let (origin, direction) = match (self.projection, self.lens) {
            (Projection::Perspective { .. }, Some(lens)) => {
                // Through the lens point towards where the pinhole ray meets the focus plane.
                let at = lens.radius * concentric_disk(u);
                let focus = lens.focus_distance * Vec3::new(plane.x, plane.y, -1.0);
                let origin = Vec3::new(at.x, at.y, 0.0);
                (origin, (focus - origin) / lens.focus_distance)
            }
            (Projection::Perspective { .. }, None) => {
                (Vec3::ZERO, Vec3::new(plane.x, plane.y, -1.0))
            }
            (Projection::Orthographic { .. }, _) => (Vec3::new(plane.x, plane.y, 0.0), Vec3::NEG_Z),
        };
        let moved;
        let world_from_camera = match &self.motion {
            None => &self.world_from_camera,
            Some(motion) => {
                moved = motion.at(time);
                &moved
            }
        };
        Ray {
            origin: world_from_camera.transform_point3(origin),
            direction: world_from_camera.transform_vector3(direction),
            t_min: self.znear,
            t_max: f32::INFINITY,
            time,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_span_the_vertical_field_of_view() {
        let cam = Camera {
            name: String::new(),
            world_from_camera: Affine3A::from_translation(Vec3::new(0.0, 0.0, 5.0)),
            projection: Projection::Perspective {
                yfov: 90f32.to_radians(),
                aspect_ratio: None,
            },
            znear: 0.1,
            lens: None,
            focal_length: None,
            shutter: None,
            motion: None,
            source: String::new(),
        };
        let g = RayGenerator::new(&cam, 200, 100);
        let top = g.generate(100.0, 0.0);
        assert!((top.direction - Vec3::new(0.0, 1.0, -1.0)).length() < 1e-6);
        let right = g.generate(200.0, 50.0);
        assert!((right.direction - Vec3::new(2.0, 0.0, -1.0)).length() < 1e-6);
        assert_eq!(top.origin, Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(top.t_min, 0.1);
    }
}
