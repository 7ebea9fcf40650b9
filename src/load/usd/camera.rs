//! UsdGeom cameras: projection, clipping, a thin lens from `fStop` and `focusDistance`, and
//! the shutter interval.

use glam::{Affine3A, Mat4};
use openusd::sdf;

use super::UsdLoader;
use super::value::as_f64;
use crate::scene::{Camera, Projection, ThinLens};

impl UsdLoader {
    pub(super) fn add_camera(&mut self, prim: &sdf::Path, world: Mat4) {
        let where_ = prim.as_str().to_string();
        // Apertures and focal length share a unit (tenths of a scene unit), so their ratio
        // is the field of view; the defaults are USD's.
        let focal = self.get_f32(prim, "focalLength").unwrap_or(50.0);
        let horizontal = self.get_f32(prim, "horizontalAperture").unwrap_or(20.955);
        let vertical = self.get_f32(prim, "verticalAperture").unwrap_or(15.2908);
        let (znear, zfar) = match self.get(prim, "clippingRange") {
            Some(sdf::Value::Vec2f(r)) => (r.x, r.y),
            Some(sdf::Value::Vec2d(r)) => (r.x as f32, r.y as f32),
            _ => (1.0, 1e6),
        };
        // A reversed range (near beyond far) would clip everything.
        let znear = if zfar < znear {
            self.warn(format!(
                "{where_}: clippingRange ({znear}, {zfar}) is reversed; clipping from {zfar} instead"
            ));
            zfar
        } else {
            znear
        };
        let (scale, rotation, translation) = world.to_scale_rotation_translation();
        let projection = if self.get_token(prim, "projection").as_deref() == Some("orthographic") {
            // Apertures in tenths of a scene unit, here after the stage's scale.
            Projection::Orthographic {
                xmag: 0.05 * horizontal * scale.x,
                ymag: 0.05 * vertical * scale.y,
            }
        } else {
            if !(focal > 0.0 && vertical > 0.0 && horizontal > 0.0) {
                self.warn(format!(
                    "{where_}: camera with zero focal length or aperture; skipped"
                ));
                return;
            }
            Projection::Perspective {
                yfov: 2.0 * (0.5 * vertical / focal).atan(),
                aspect_ratio: Some(horizontal / vertical),
            }
        };
        // Depth of field: a thin lens of radius focal length / (2 × fStop), focused at
        // focusDistance (scene units); fStop 0, USD's default, is a pinhole.
        let focal_length = 0.1 * focal * scale.y;
        let f_stop = self.get_f32(prim, "fStop").unwrap_or(0.0);
        let focus = self.get_f32(prim, "focusDistance").unwrap_or(0.0) * scale.y;
        let lens =
            (f_stop > 0.0 && focus > 0.0 && f_stop.is_finite() && focus.is_finite()).then(|| {
                ThinLens {
                    radius: focal_length / (2.0 * f_stop),
                    focus_distance: focus,
                }
            });
        // Frame-relative shutter interval (UsdGeomCamera; both 0 by default: no blur).
        let open = self
            .get(prim, "shutter:open")
            .as_ref()
            .and_then(as_f64)
            .unwrap_or(0.0);
        let close = self
            .get(prim, "shutter:close")
            .as_ref()
            .and_then(as_f64)
            .unwrap_or(0.0);
        let shutter =
            (open.is_finite() && close.is_finite() && close > open).then_some([open, close]);
        self.builder.add_camera(Camera {
            name: where_.clone(),
            world_from_camera: Affine3A::from_rotation_translation(
                rotation.normalize(),
                translation,
            ),
            projection,
            znear: znear * scale.y,
            lens,
            focal_length: (focal_length > 0.0).then_some(focal_length),
            shutter,
            motion: None,
            source: where_,
        });
    }
}
