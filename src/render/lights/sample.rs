//! What every kind of light gives next-event estimation: a point (or direction) on it as
//! seen from the shading point, the radiance it sends there and the density it was drawn
//! with.

use glam::Vec3;

/// A point drawn on a light, as seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point on the light.
    pub point: Vec3,
    /// Bound on the rounding error of `point`, per axis.
    pub point_error: Vec3,
    /// The light's unit normal there (front side).
    pub normal: Vec3,
    /// Unit direction from the shading point to the light point.
    pub wi: Vec3,
    /// Distance from the shading point to the light point.
    pub distance: f32,
    /// Radiance leaving the light towards the shading point.
    pub radiance: Vec3,
    /// Solid-angle density of `wi` at the shading point; for a punctual light, the
    /// probability of having picked it.
    pub pdf: f32,
    /// True for a punctual light: `radiance` is then the irradiance it brings to a surface
    /// facing it, and no ray can find the light, so there is nothing to weigh against.
    pub is_delta: bool,
}
