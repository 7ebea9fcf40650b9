//! Cameras as the file describes them; the renderer turns them into ray generators.

use glam::Affine3A;

/// The projection of a camera that looks down its local −Z axis with +Y up (glTF convention).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole camera.
    Perspective {
        /// Vertical field of view in radians.
        yfov: f32,
        /// Width / height the file asks for, if any.
        aspect_ratio: Option<f32>,
    },
    /// Parallel projection.
    Orthographic {
        /// Half the width of the view in scene units.
        xmag: f32,
        /// Half the height of the view in scene units.
        ymag: f32,
    },
}

/// A camera placed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Name from the file (may be empty).
    pub name: String,
    /// Camera-to-world transform.
    pub world_from_camera: Affine3A,
    /// How the camera projects.
    pub projection: Projection,
    /// Distance to the near clipping plane: nothing closer is seen.
    pub znear: f32,
    /// Where the camera came from, for messages.
    pub source: String,
}

impl Camera {
    /// The aspect ratio (width / height) this camera prefers, if it has one.
    pub fn aspect_ratio(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { aspect_ratio, .. } => aspect_ratio,
            Projection::Orthographic { xmag, ymag } => Some(xmag / ymag),
        }
    }
}

impl Camera {
    /// A perspective camera that frames `bounds`: it looks down −Z from the +Z side (the
    /// front view in glTF's Y-up convention) with a 40° vertical field of view, far enough
    /// back that the bounding sphere fits both vertically and horizontally at `aspect`.
    pub fn framing(bounds: &crate::scene::Aabb, aspect: f32) -> Camera {
        let yfov = 40f32.to_radians();
        let (center, radius) = if bounds.is_empty() {
            (glam::Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (0.5 * bounds.extent().length()).max(1e-3))
        };
        let half_y = 0.5 * yfov;
        let half_x = (half_y.tan() * aspect).atan();
        let distance = radius / half_y.min(half_x).sin();
        Camera {
            name: "default".into(),
            world_from_camera: Affine3A::from_translation(center + glam::Vec3::Z * distance),
            projection: Projection::Perspective {
                yfov,
                aspect_ratio: Some(aspect),
            },
            znear: 1e-3 * distance,
            source: "default camera framing the scene".into(),
        }
    }
}
