//! Rays with a parametric extent.

use glam::Vec3;

/// A ray `origin + t·direction` for `t` in the open interval (`t_min`, `t_max`).
///
/// The direction need not be unit length; distances are in units of `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (any non-zero length).
    pub direction: Vec3,
    /// Hits at or before this parameter are ignored.
    pub t_min: f32,
    /// Hits at or after this parameter are ignored.
    pub t_max: f32,
    /// Shutter time in [0, 1] at which the ray sees the scene (0 for still scenes).
    pub time: f32,
}

impl Ray {
    /// A ray from `origin` along `direction` with `t` in (0, ∞).
    pub fn new(origin: Vec3, direction: Vec3) -> Ray {
        Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: f32::INFINITY,
            time: 0.0,
        }
    }

    /// The same ray at shutter time `time`.
    pub fn at_time(self, time: f32) -> Ray {
        Ray { time, ..self }
    }

    /// The same ray limited to `t < t_max`.
    pub fn with_t_max(self, t_max: f32) -> Ray {
        Ray { t_max, ..self }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}
