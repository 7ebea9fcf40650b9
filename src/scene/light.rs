//! Lights that are not surfaces of the scene's meshes: glTF's `KHR_lights_punctual` (points,
//! spots, suns: reached only by sampling them, never by a ray) and lamps with a size that
//! are not geometry (a sphere: rays see its radiance and go on through it, and it casts no
//! shadow, as lamps in Cycles).

use std::f32::consts::PI;

use glam::Vec3;

/// What a punctual light is and where it shines, in world space and radiometric units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Emits `intensity` (W/sr) equally in all directions from `position`.
    Point {
        /// Where the light is.
        position: Vec3,
        /// Radiant intensity per channel (W/sr).
        intensity: Vec3,
        /// Distance beyond which the light has no effect (glTF `range`); `None`: unlimited.
        range: Option<f32>,
    },
    /// A point light restricted to a cone around `direction`, fading between the inner and
    /// the outer cone angle as the glTF specification describes.
    Spot {
        /// Where the light is.
        position: Vec3,
        /// Unit axis of the cone, the direction the light travels.
        direction: Vec3,
        /// Radiant intensity on the axis (W/sr).
        intensity: Vec3,
        /// Cosine of the angle within which the light is at full intensity.
        cos_inner: f32,
        /// Cosine of the angle beyond which the light is dark.
        cos_outer: f32,
        /// Distance beyond which the light has no effect; `None`: unlimited.
        range: Option<f32>,
    },
    /// A sphere of uniform radiance: a lamp with a radius (Blender's point and spot lamps,
    /// USD's `SphereLight`), optionally restricted to a spot cone: each point of the sphere
    /// sends light in direction ω scaled by [`LightKind::Spot`]'s falloff of ω, as Cycles'
    /// spot lamps with a radius do.
    Sphere {
        /// Centre.
        position: Vec3,
        /// Radius (> 0).
        radius: f32,
        /// Radiance leaving every point of the surface (W·sr⁻¹·m⁻²).
        radiance: Vec3,
        /// The spot cone: unit axis, cosine of the inner and of the outer angle.
        spot: Option<(Vec3, f32, f32)>,
        /// When false, camera rays pass it unseen (Blender's lamps, UsdLux lights).
        camera_visible: bool,
        /// Blender's Soft Falloff (on by default): the lamp shines as a disc of its radius
        /// turned towards the point it lights, as Cycles renders it, so light fades
        /// smoothly close to it instead of rising like a ball's.
        soft: bool,
    },
    /// Parallel light from infinitely far away, like the sun.
    Directional {
        /// Unit direction the light travels.
        direction: Vec3,
        /// Irradiance on a surface facing the light (W/m²).
        irradiance: Vec3,
    },
}

/// A named punctual light.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Name for messages.
    pub name: String,
    /// Kind, placement and strength.
    pub kind: LightKind,
    /// Where this light came from, for messages.
    pub source: String,
}

impl LightKind {
    /// Radiant intensity (W/sr) towards `wo`, a unit direction leaving the light, at
    /// distance `distance`: the spot cone and the range window applied. Not for
    /// directional lights, which have no intensity.
    pub fn intensity_towards(&self, wo: Vec3, distance: f32) -> Vec3 {
        match *self {
            LightKind::Point {
                intensity, range, ..
            } => intensity * range_window(distance, range),
            LightKind::Spot {
                direction,
                intensity,
                cos_inner,
                cos_outer,
                range,
                ..
            } => {
                intensity
                    * spot_falloff(direction.dot(wo), cos_inner, cos_outer)
                    * range_window(distance, range)
            }
            LightKind::Sphere {
                radius, radiance, ..
            } => {
                // Seen from far away, a sphere is a disc of area πr².
                radiance * PI * radius * radius * self.spot_factor(wo)
            }
            LightKind::Directional { .. } => Vec3::ZERO,
        }
    }

    /// A sphere's spot-cone falloff for light leaving it in unit direction `wo`; 1 for a
    /// sphere without a cone and for every other kind.
    pub fn spot_factor(&self, wo: Vec3) -> f32 {
        match *self {
            LightKind::Sphere {
                spot: Some((direction, cos_inner, cos_outer)),
                ..
            } => spot_falloff(direction.dot(wo), cos_inner, cos_outer),
            _ => 1.0,
        }
    }
}

impl LightKind {
    /// The largest radiant intensity (W/sr, mean over channels) it sends in any direction:
    /// divided by a squared distance, a bound on the irradiance it brings (exact for a
    /// point), which the light tree weighs lights by. Zero for a directional light, which
    /// brings an irradiance instead.
    pub fn peak_intensity(&self) -> f32 {
        match *self {
            LightKind::Point { intensity, .. } | LightKind::Spot { intensity, .. } => {
                mean(intensity)
            }
            // Seen from anywhere, a sphere is a disc of area πr².
            LightKind::Sphere {
                radius, radiance, ..
            } => PI * radius * radius * mean(radiance),
            LightKind::Directional { .. } => 0.0,
        }
    }
}

impl LightKind {
    /// Emitted power (W), mean over channels: what light selection weighs and `--inspect`
    /// prints. A spot counts its cone up to halfway through the falloff; a directional
    /// light, what crosses the disc of the sphere (radius `scene_radius`) around the scene.
    pub fn power(&self, scene_radius: f32) -> f32 {
        match *self {
            LightKind::Point { intensity, .. } => 4.0 * PI * mean(intensity),
            LightKind::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * mean(intensity),
            LightKind::Sphere {
                radius,
                radiance,
                spot,
                ..
            } => {
                // π·L per unit area over 4πr²; a cone keeps its share of the directions.
                let share = spot.map_or(1.0, |(_, cos_inner, cos_outer)| {
                    0.5 * (1.0 - 0.5 * (cos_inner + cos_outer))
                });
                4.0 * PI * PI * radius * radius * mean(radiance) * share
            }
            LightKind::Directional { irradiance, .. } => {
                PI * scene_radius * scene_radius * mean(irradiance)
            }
        }
    }
}

/// Mean of the three channels.
fn mean(v: Vec3) -> f32 {
    v.element_sum() / 3.0
}

/// The glTF `KHR_lights_punctual` spot attenuation: linear in the cosine between the outer
/// and inner cone, squared.
fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
    let t = ((cos_angle - cos_outer) * scale).clamp(0.0, 1.0);
    t * t
}

/// The window the glTF specification recommends for `range`, which takes the light to zero
/// smoothly at that distance instead of cutting it off: (1 − (d/range)⁴)², clamped.
fn range_window(distance: f32, range: Option<f32>) -> f32 {
    match range {
        Some(r) if r > 0.0 => {
            let x = distance / r;
            (1.0 - x * x * x * x).clamp(0.0, 1.0).powi(2)
        }
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spot_is_full_inside_the_inner_cone_and_dark_outside_the_outer() {
        let (inner, outer) = (20f32.to_radians().cos(), 30f32.to_radians().cos());
        assert_eq!(spot_falloff(1.0, inner, outer), 1.0);
        assert_eq!(spot_falloff(inner, inner, outer), 1.0);
        assert_eq!(spot_falloff(outer, inner, outer), 0.0);
        assert_eq!(spot_falloff(0.5, inner, outer), 0.0);
        let halfway = spot_falloff(0.5 * (inner + outer), inner, outer);
        assert!((halfway - 0.25).abs() < 1e-5, "{halfway}");
    }

    #[test]
    fn range_window_fades_to_zero_at_the_range() {
        assert_eq!(range_window(5.0, None), 1.0);
        assert_eq!(range_window(0.0, Some(2.0)), 1.0);
        assert_eq!(range_window(2.0, Some(2.0)), 0.0);
        assert_eq!(range_window(3.0, Some(2.0)), 0.0);
        let w = range_window(1.0, Some(2.0));
        assert!((w - (1.0f32 - 1.0 / 16.0).powi(2)).abs() < 1e-6);
    }
}
