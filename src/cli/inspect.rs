//! `gridtrace --inspect`: a plain-text account of what a loader made of a file, so a user can
//! see how each material was mapped, how strong each light is and what was skipped.

use std::fmt::Write;

use glam::Vec3;

use crate::render::{Bsdf, EmissiveTriangles};
use crate::scene::{AlphaMode, LightKind, Material, Projection, Scene};

/// The report: meshes, instances, materials with their class, textures, lights with their
/// power, cameras and every warning.
pub fn describe(scene: &Scene, warnings: &[String]) -> String {
    let mut out = String::new();
    let triangles: usize = scene.meshes.iter().map(|m| m.indices.len()).sum();
    let bounds = scene.bounds();
    let _ = writeln!(
        out,
        "meshes: {} ({triangles} triangles); instances: {} ({} triangles after instancing)",
        scene.meshes.len(),
        scene.instances.len(),
        scene.instanced_triangle_count()
    );
    if !bounds.is_empty() {
        let _ = writeln!(
            out,
            "bounds: {} to {}",
            vector(bounds.min),
            vector(bounds.max)
        );
    }
    let emitted = EmissiveTriangles::collect(scene).power_by_material(scene);
    let _ = writeln!(out, "materials: {}", scene.materials.len());
    for (i, m) in scene.materials.iter().enumerate() {
        let _ = writeln!(
            out,
            "  {i} '{}': {}",
            m.name,
            material_summary(m, emitted[i])
        );
    }
    let _ = writeln!(out, "textures: {}", scene.textures.len());
    for (i, t) in scene.textures.iter().enumerate() {
        let _ = writeln!(out, "  {i} {}: {}x{}", t.name, t.width, t.height);
    }
    let _ = writeln!(out, "lights: {}", scene.lights.len());
    for light in &scene.lights {
        let _ = writeln!(
            out,
            "  '{}' ({}): {}",
            light.name,
            light.source,
            light_summary(&light.kind)
        );
    }
    let _ = writeln!(out, "{}", environment_summary(scene));
    describe_cameras(&mut out, scene);
    let _ = writeln!(out, "warnings: {}", warnings.len());
    for w in warnings {
        let _ = writeln!(out, "  {w}");
    }
    out
}

/// The environment line: none, a constant radiance, or a map with its scale and mean.
fn environment_summary(scene: &Scene) -> String {
    let Some(e) = &scene.environment else {
        return "environment: none".to_string();
    };
    let what = match &e.map {
        None => format!("constant radiance {}", vector(e.tint)),
        Some(m) => format!(
            "map {} ({}x{}) × {}, mean radiance {}",
            m.name,
            m.width,
            m.height,
            vector(e.tint),
            vector(e.mean_radiance())
        ),
    };
    let hidden = if e.camera_visible {
        ""
    } else {
        ", hidden from the camera"
    };
    format!("environment ({}): {what}{hidden}", e.source)
}

/// The cameras: projection, position and near plane of each.
fn describe_cameras(out: &mut String, scene: &Scene) {
    let _ = writeln!(out, "cameras: {}", scene.cameras.len());
    for (i, c) in scene.cameras.iter().enumerate() {
        let position = c.world_from_camera.transform_point3(Vec3::ZERO);
        let projection = match c.projection {
            Projection::Perspective { yfov, .. } => {
                format!(
                    "perspective, vertical field of view {:.1}°",
                    yfov.to_degrees()
                )
            }
            Projection::Orthographic { xmag, ymag } => {
                format!("orthographic, {xmag} x {ymag}")
            }
        };
        let _ = writeln!(
            out,
            "  {i} '{}' ({}): {projection}, at {}, near {}",
            c.name,
            c.source,
            vector(position),
            c.znear
        );
    }
}

fn vector(v: Vec3) -> String {
    format!("({:.3}, {:.3}, {:.3})", v.x, v.y, v.z)
}

fn material_summary(m: &Material, emitted: f32) -> String {
    let p = &m.pbr;
    let lobes = Bsdf::new(p, true).lobe_names();
    let mut s = format!(
        "{}; base colour {}, metallic {}, roughness {}, ior {}",
        if lobes.is_empty() {
            "black".to_string()
        } else {
            lobes.join(" + ")
        },
        vector(p.base_colour),
        significant(p.metallic),
        significant(p.roughness),
        significant(p.ior)
    );
    if p.specular != 1.0 {
        let _ = write!(s, ", specular {}", significant(p.specular));
    }
    if p.specular_colour != Vec3::ONE {
        let _ = write!(s, ", specular tint {}", vector(p.specular_colour));
    }
    if p.transmission > 0.0 {
        let _ = write!(s, ", transmission {}", significant(p.transmission));
    }
    if p.clearcoat > 0.0 {
        let _ = write!(
            s,
            ", coat {} roughness {}",
            significant(p.clearcoat),
            significant(p.clearcoat_roughness)
        );
    }
    if p.sheen_colour != Vec3::ZERO {
        let _ = write!(
            s,
            ", sheen {} roughness {} ({:?})",
            vector(p.sheen_colour),
            significant(p.sheen_roughness),
            p.sheen_model
        );
    }
    if p.anisotropy.strength > 0.0 {
        let _ = write!(
            s,
            ", anisotropy {} at {}° ({:?})",
            significant(p.anisotropy.strength),
            significant(p.anisotropy.rotation.to_degrees()),
            p.anisotropy.model
        );
    }
    if m.is_emissive() {
        let _ = write!(
            s,
            "; area light, radiance {}, {} W emitted",
            vector(m.emission),
            significant(emitted)
        );
    }
    if m.lamp {
        s.push_str("; a lamp (casts no shadow, rays pass it)");
    }
    if !m.double_sided {
        s.push_str("; one-sided");
    }
    let t = &m.textures;
    let textures: Vec<&str> = [
        (t.base_colour.is_some(), "base colour"),
        (t.emissive.is_some(), "emission"),
        (t.metallic.is_some(), "metallic"),
        (t.roughness.is_some(), "roughness"),
        (t.transmission.is_some(), "transmission"),
        (t.clearcoat.is_some(), "coat"),
        (t.clearcoat_roughness.is_some(), "coat roughness"),
        (t.specular.is_some(), "specular"),
        (t.specular_colour.is_some(), "specular colour"),
        (t.sheen_colour.is_some(), "sheen colour"),
        (t.sheen_roughness.is_some(), "sheen roughness"),
        (t.normal.is_some(), "normal map"),
    ]
    .into_iter()
    .filter_map(|(used, name)| used.then_some(name))
    .collect();
    if !textures.is_empty() {
        let _ = write!(s, "; textures: {}", textures.join(", "));
    }
    match m.alpha_mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask { cutoff } => {
            let _ = write!(s, "; alpha cutout at {cutoff}");
        }
        AlphaMode::Blend => s.push_str("; alpha blended"),
    }
    if m.absorption != Vec3::ZERO {
        let _ = write!(s, "; absorption {} per unit", vector(m.absorption));
    }
    s
}

fn light_summary(kind: &LightKind) -> String {
    match *kind {
        LightKind::Point {
            position,
            intensity,
            range,
        } => format!(
            "point at {}, intensity {} W/sr, {} W{}",
            vector(position),
            vector(intensity),
            significant(kind.power(0.0)),
            range.map_or(String::new(), |r| format!(", range {r}"))
        ),
        LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => format!(
            "spot at {} towards {}, intensity {} W/sr, cone {:.1}° to {:.1}°",
            vector(position),
            vector(direction),
            vector(intensity),
            cos_inner.acos().to_degrees(),
            cos_outer.acos().to_degrees()
        ),
        LightKind::Sphere {
            position,
            radius,
            radiance,
            spot,
            camera_visible,
            soft,
        } => format!(
            "sphere at {}, radius {radius}, radiance {}, {} W{}{}{}",
            vector(position),
            vector(radiance),
            significant(kind.power(0.0)),
            spot.map_or(String::new(), |(d, inner, outer)| format!(
                ", cone towards {} {:.1}° to {:.1}°",
                vector(d),
                inner.acos().to_degrees(),
                outer.acos().to_degrees()
            )),
            if camera_visible {
                ""
            } else {
                ", hidden from the camera"
            },
            if soft { ", soft falloff" } else { "" }
        ),
        LightKind::Directional {
            direction,
            irradiance,
        } => format!(
            "directional towards {}, irradiance {} W/m²",
            vector(direction),
            vector(irradiance)
        ),
    }
}

/// Four significant digits.
fn significant(v: f32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}
