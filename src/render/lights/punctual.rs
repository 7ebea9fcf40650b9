//! The scene's own lights — point, spot and directional lights, and sphere lamps (points
//! and spots with a radius) — with their bounds for the light tree and their samples.
//! Points, spots and suns are deltas: sampled, never hit. Sphere lamps are sampled over
//! the cone they subtend ([`sphere`]) and found by rays, which go on through them.

use glam::{Vec2, Vec3};

use super::sample::LightSample;
use super::sphere;
use super::tree::{Cone, Distant, LightBounds, TreeInput};
use crate::geometry::Aabb;
use crate::scene::LightKind;

/// Where `light` can send light from and to and how strongly, for the light tree; a
/// directional light competes by the irradiance it brings, from its direction.
pub fn tree_input(light: &LightKind) -> TreeInput {
    let at = |p: Vec3| Aabb { min: p, max: p };
    let surface = |bounds, normals| LightBounds {
        bounds,
        intensity: light.peak_intensity(),
        normals,
        cos_emission: 0.0,
        two_sided: false,
    };
    // Nothing beyond the outer cone.
    let cone = |bounds, axis, cos_outer| LightBounds {
        cos_emission: 1.0,
        ..surface(
            bounds,
            Cone {
                axis,
                cos_angle: cos_outer,
            },
        )
    };
    TreeInput::Placed(match *light {
        LightKind::Directional {
            direction,
            irradiance,
        } => {
            return TreeInput::Infinite(Distant {
                irradiance: irradiance.element_sum() / 3.0,
                towards: Some(-direction),
            });
        }
        LightKind::Point { position, .. } => surface(at(position), Cone::ALL),
        LightKind::Spot {
            position,
            direction,
            cos_outer,
            ..
        } => cone(at(position), direction, cos_outer),
        LightKind::Sphere {
            position,
            radius,
            spot,
            ..
        } => {
            let ball = Aabb {
                min: position - Vec3::splat(radius),
                max: position + Vec3::splat(radius),
            };
            match spot {
                // Every point of the ball sends light only within the cone's directions
                // (its falloff depends on the direction alone).
                Some((axis, _, cos_outer)) => cone(ball, axis, cos_outer),
                None => surface(ball, Cone::ALL),
            }
        }
    })
}

/// The light `light` brings to `p`, chosen with probability `pmf`; `far` is a distance
/// that takes a segment from `p` past the whole scene, where a directional light's shadow
/// ray starts.
pub fn sample(light: &LightKind, pmf: f32, p: Vec3, far: f32, u: Vec2) -> Option<LightSample> {
    let (point, radiance) = match *light {
        LightKind::Sphere {
            position,
            radius,
            radiance,
            soft,
            ..
        } => {
            let s = if soft {
                sphere::sample_disc(position, radius, p, u)?
            } else {
                sphere::sample(position, radius, p, u)?
            };
            let spot = light.spot_factor(-s.wi);
            return Some(LightSample {
                point: s.point,
                point_error: Vec3::splat(1e-6 * (radius + position.abs().max_element())),
                normal: s.normal,
                wi: s.wi,
                distance: s.distance,
                radiance: radiance * spot,
                pdf: pmf * s.pdf,
                is_delta: false,
            });
        }
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
            let distance = position.distance(p);
            if distance == 0.0 {
                return None;
            }
            let wi = (position - p) / distance;
            let intensity = light.intensity_towards(-wi, distance);
            (position, intensity / (distance * distance))
        }
        LightKind::Directional {
            direction,
            irradiance,
        } => (p - far * direction, irradiance),
    };
    let distance = point.distance(p);
    let wi = (point - p) / distance;
    Some(LightSample {
        point,
        point_error: Vec3::ZERO,
        normal: -wi,
        wi,
        distance,
        radiance,
        pdf: pmf,
        is_delta: true,
    })
}

/// The radiance a ray from `origin` along unit direction `d` meets in sphere lamp `light`
/// before `t_max`, and where: `None` for any other light, one the ray misses, or one a
/// camera ray (`camera`) may not see. A soft-falloff lamp's disc faces `vertex`, where the
/// path last scattered.
pub fn met_along(
    light: &LightKind,
    vertex: Vec3,
    origin: Vec3,
    d: Vec3,
    t_max: f32,
    camera: bool,
) -> Option<(Vec3, f32)> {
    let LightKind::Sphere {
        position,
        radius,
        radiance,
        camera_visible,
        soft,
        ..
    } = *light
    else {
        return None;
    };
    if camera && !camera_visible {
        return None;
    }
    let t = if soft {
        sphere::intersect_disc(position, radius, vertex, origin, d, 0.0, t_max)?
    } else {
        sphere::intersect(position, radius, origin, d, 0.0, t_max)?
    };
    Some((radiance * light.spot_factor(-d), t))
}

/// The solid-angle density with which [`sample`] at `vertex` draws a point of sphere lamp
/// `light` in unit direction `d`, once chosen.
pub fn sphere_pdf(light: &LightKind, vertex: Vec3, d: Vec3) -> f32 {
    match *light {
        LightKind::Sphere {
            position,
            radius,
            soft: true,
            ..
        } => sphere::pdf_disc(position, radius, vertex, d),
        LightKind::Sphere {
            position, radius, ..
        } => sphere::pdf(position, radius, vertex),
        _ => 0.0,
    }
}
