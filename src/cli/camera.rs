//! Which camera renders, with what lens, at what image size.

use anyhow::{Result, anyhow};
use glam::Vec3;

use crate::scene::{Camera, Projection, Scene, ThinLens};

/// Image height used when neither --width nor --height is given.
pub const DEFAULT_HEIGHT: u32 = 512;

/// How the record names a camera: its name and where it came from, and its lens.
pub fn camera_label(camera: &Camera) -> String {
    match camera.lens {
        Some(l) => format!(
            "'{}' ({}) lens radius {} focus {}",
            camera.name, camera.source, l.radius, l.focus_distance
        ),
        None => format!("'{}' ({})", camera.name, camera.source),
    }
}

/// `camera` with the depth of field `--fstop` and `--focus-distance` ask for: f-number 0
/// removes it; the focal length is the camera's or, without one, that of a 24 mm-high
/// (full-frame) sensor at its vertical field of view with scene units taken as metres; the
/// focus distance is the option's, the camera's, or the distance to the scene's centre
/// along the view.
pub fn with_depth_of_field(
    mut camera: Camera,
    fstop: Option<f32>,
    focus_distance: Option<f32>,
    scene: &Scene,
) -> Camera {
    let Projection::Perspective { yfov, .. } = camera.projection else {
        return camera;
    };
    let focus = focus_distance
        .or(camera.lens.map(|l| l.focus_distance))
        .unwrap_or_else(|| {
            let forward = camera
                .world_from_camera
                .transform_vector3(Vec3::NEG_Z)
                .normalize();
            let eye = camera.world_from_camera.transform_point3(Vec3::ZERO);
            (scene.bounds().center() - eye)
                .dot(forward)
                .max(camera.znear.max(1e-3))
        });
    let radius = match fstop {
        Some(n) if n > 0.0 => {
            let focal = camera
                .focal_length
                .unwrap_or_else(|| 0.012 / (0.5 * yfov).tan());
            Some(focal / (2.0 * n))
        }
        Some(_) => None,
        None => camera.lens.map(|l| l.radius),
    };
    camera.lens = radius.map(|radius| ThinLens {
        radius,
        focus_distance: focus,
    });
    camera
}

/// Which camera renders: one of the scene's, or one made to frame it. Chosen once, by
/// name or index, and taken from whichever reading of the scene renders (the scene read
/// over a shutter keeps its cameras in file order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraPick {
    /// The scene's camera of this index.
    Index(usize),
    /// A default camera framing the scene from a three-quarter view.
    Framing,
}

impl CameraPick {
    /// The camera `wanted` names (by index, name or node name), else the first one, else a
    /// framing camera.
    pub fn choose(scene: &Scene, wanted: Option<&str>) -> Result<CameraPick> {
        let Some(spec) = wanted else {
            return Ok(if scene.cameras.is_empty() {
                CameraPick::Framing
            } else {
                CameraPick::Index(0)
            });
        };
        if let Ok(index) = spec.parse::<usize>() {
            return match scene.cameras.get(index) {
                Some(_) => Ok(CameraPick::Index(index)),
                None => Err(anyhow!("no camera {index}; {}", camera_list(scene))),
            };
        }
        scene
            .cameras
            .iter()
            .position(|c| c.name == spec || c.source.ends_with(&format!("'{spec}'")))
            .map(CameraPick::Index)
            .ok_or_else(|| anyhow!("no camera named '{spec}'; {}", camera_list(scene)))
    }

    /// The camera in `scene`; a framing camera fits the image's aspect when both sides are
    /// given.
    pub fn camera(self, scene: &Scene, width: Option<u32>, height: Option<u32>) -> Result<Camera> {
        match self {
            CameraPick::Index(index) => scene
                .cameras
                .get(index)
                .cloned()
                .ok_or_else(|| anyhow!("no camera {index}; {}", camera_list(scene))),
            CameraPick::Framing => {
                let aspect = match (width, height) {
                    (Some(w), Some(h)) => w as f32 / h as f32,
                    _ => 1.0,
                };
                Ok(Camera::framing(&scene.bounds(), aspect))
            }
        }
    }
}

/// The scene's cameras, for an error naming one that is not there.
fn camera_list(scene: &Scene) -> String {
    if scene.cameras.is_empty() {
        return "the scene has no cameras".to_string();
    }
    let names: Vec<String> = scene
        .cameras
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{i} '{}' ({})", c.name, c.source))
        .collect();
    format!("cameras: {}", names.join(", "))
}

/// The camera asked for, the first one, or one that frames the scene.
pub fn choose_camera(
    scene: &Scene,
    wanted: Option<&str>,
    width: Option<u32>,
    height: Option<u32>,
) -> Result<Camera> {
    CameraPick::choose(scene, wanted)?.camera(scene, width, height)
}

/// Image size from the options, filling a missing side from the camera's aspect ratio.
pub fn image_size(width: Option<u32>, height: Option<u32>, aspect: Option<f32>) -> (u32, u32) {
    let aspect = aspect.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
    let from_aspect = |x: f32| (x.round() as u32).clamp(1, 65536);
    match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, from_aspect(w as f32 / aspect)),
        (None, Some(h)) => (from_aspect(h as f32 * aspect), h),
        (None, None) => (from_aspect(DEFAULT_HEIGHT as f32 * aspect), DEFAULT_HEIGHT),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_size_follows_the_camera_aspect() {
        assert_eq!(image_size(None, None, Some(1.5)), (768, 512));
        assert_eq!(image_size(Some(300), None, Some(1.5)), (300, 200));
        assert_eq!(image_size(None, Some(100), None), (100, 100));
        assert_eq!(image_size(Some(7), Some(9), Some(2.0)), (7, 9));
    }
}
