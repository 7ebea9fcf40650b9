//! Cameras as the file describes them; the renderer turns them into ray generators.

use glam::Affine3A;

use super::Motion;

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

/// A thin lens (Kolb et al. 1995; pbrt-v4 §5.2.3): rays leave a disc of `radius` and meet
/// where the pinhole ray meets the plane `focus_distance` in front of the camera, so what
/// lies on that plane is sharp and the rest is blurred by its circle of confusion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Radius of the aperture in scene units (focal length / (2 × f-number)).
    pub radius: f32,
    /// Distance from the camera to the plane in focus, in scene units.
    pub focus_distance: f32,
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
    /// Depth of field, if the camera has it (perspective cameras only).
    pub lens: Option<ThinLens>,
    /// Focal length in scene units where the file says it (USD), for `--fstop`.
    pub focal_length: Option<f32>,
    /// When the shutter opens and closes, in frames relative to the frame rendered, where
    /// the file says it (USD `shutter:open`, `shutter:close`).
    pub shutter: Option<[f64; 2]>,
    /// `world_from_camera` over the shutter, when the camera moves.
    pub motion: Option<Motion>,
    /// Where the camera came from, for messages.
    pub source: String,
}

impl Camera {
    /// Why this camera cannot make an image, if it cannot: a field of view that is not
    /// between 0 and 180°, an orthographic view of no size, or a transform that is not
    /// finite or collapses a dimension (a zero matrix, a zero scale), all of which would
    /// render a uniform image.
    pub fn validate(&self) -> Result<(), String> {
        match self.projection {
            Projection::Perspective { yfov, aspect_ratio } => {
                if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
                    return Err(format!(
                        "vertical field of view {yfov} rad is not between 0 and π"
                    ));
                }
                if let Some(a) = aspect_ratio.filter(|a| !(a.is_finite() && *a > 0.0)) {
                    return Err(format!("aspect ratio {a} is not a positive number"));
                }
            }
            Projection::Orthographic { xmag, ymag } => {
                let positive = |m: f32| m.is_finite() && m != 0.0;
                if !(positive(xmag) && positive(ymag)) {
                    return Err(format!(
                        "orthographic view {xmag}x{ymag} has no size (xmag and ymag must be non-zero)"
                    ));
                }
            }
        }
        if !self.znear.is_finite() || self.znear < 0.0 {
            return Err(format!(
                "near clipping distance {} is not a finite, non-negative distance",
                self.znear
            ));
        }
        let m = self.world_from_camera;
        let determinant = m.matrix3.determinant();
        if !(m.matrix3.is_finite() && m.translation.is_finite()) || determinant.abs() < 1e-12 {
            return Err(
                "its transform is not finite or is degenerate (a zero matrix or a zero scale)"
                    .into(),
            );
        }
        Ok(())
    }

    /// The aspect ratio (width / height) this camera prefers, if it has one.
    pub fn aspect_ratio(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { aspect_ratio, .. } => aspect_ratio,
            Projection::Orthographic { xmag, ymag } => Some(xmag / ymag),
        }
    }
}

impl Camera {
    /// A perspective camera that frames `bounds` from a three-quarter view, as model
    /// viewers open a model: from the front (+Z, glTF's forward) turned 35° towards +X and
    /// 25° above the horizon (Y up), looking at the centre with a 40° vertical field of view,
    /// far enough back that the bounding sphere fits both vertically and horizontally at
    /// `aspect`. A flat object lying or standing in any axis plane is seen at an angle.
    pub fn framing(bounds: &crate::geometry::Aabb, aspect: f32) -> Camera {
        let yfov = 40f32.to_radians();
        let (center, radius) = if bounds.is_empty() {
            (glam::Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (0.5 * bounds.extent().length()).max(1e-3))
        };
        let half_y = 0.5 * yfov;
        let half_x = (half_y.tan() * aspect).atan();
        let distance = radius / half_y.min(half_x).sin();
        let (azimuth, elevation) = (35f32.to_radians(), 25f32.to_radians());
        let towards_camera = glam::Vec3::new(
            azimuth.sin() * elevation.cos(),
            elevation.sin(),
            azimuth.cos() * elevation.cos(),
        );
        let eye = center + distance * towards_camera;
        // Camera space looks down −Z with +Y up.
        let back = towards_camera;
        let right = glam::Vec3::Y.cross(back).normalize();
        let up = back.cross(right);
        Camera {
            name: "default".into(),
            world_from_camera: Affine3A::from_cols(
                right.into(),
                up.into(),
                back.into(),
                eye.into(),
            ),
            projection: Projection::Perspective {
                yfov,
                aspect_ratio: Some(aspect),
            },
            znear: 1e-3 * distance,
            lens: None,
            focal_length: None,
            shutter: None,
            motion: None,
            source: "default camera framing the scene".into(),
        }
    }
}
