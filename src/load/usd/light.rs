//! UsdLux lights and UsdGeom cameras, as scene lights and cameras.

use glam::{Affine3A, Mat3, Mat4, Vec3};
use openusd::sdf;

use super::value::{as_bool, as_vec3};
use super::{DISK_SEGMENTS, UsdLoader};
use crate::scene::{Environment, Light, LightKind, Material};

impl UsdLoader {
    /// A UsdLux light's `intensity × 2^exposure × color`, tinted by its colour temperature
    /// when enabled.
    pub(super) fn light_strength(&self, prim: &sdf::Path) -> Vec3 {
        let intensity = self.get_f32(prim, "inputs:intensity").unwrap_or(1.0);
        let exposure = self.get_f32(prim, "inputs:exposure").unwrap_or(0.0);
        let colour = self
            .get(prim, "inputs:color")
            .as_ref()
            .and_then(as_vec3)
            .unwrap_or(Vec3::ONE);
        // Colour temperature tints relative to 6500 K, USD's default white point, which
        // Blender writes on every light and Cycles renders white.
        let enabled = self
            .get(prim, "inputs:enableColorTemperature")
            .as_ref()
            .and_then(as_bool);
        let colour = if enabled == Some(true) {
            let kelvin = self
                .get_f32(prim, "inputs:colorTemperature")
                .unwrap_or(6500.0);
            colour * blackbody_tint(kelvin)
        } else {
            colour
        };
        colour * intensity * exposure.exp2()
    }

    /// A `DomeLight` or `DomeLight_1`: radiance intensity × 2^exposure × color from every
    /// direction the scene leaves open, times its latitude–longitude `texture:file` if it
    /// has one. The map is read in the OpenEXR convention, its pole turned onto the stage's
    /// up axis (below), then placed by the dome's transform.
    pub(super) fn add_dome(&mut self, prim: &sdf::Path, world: Mat4) {
        let where_ = prim.as_str().to_string();
        let tint = self.light_strength(prim);
        if !tint.is_finite() || tint.min_element() < 0.0 {
            self.warn(format!(
                "{where_}: negative or non-finite dome light; skipped"
            ));
            return;
        }
        let file = match self.get(prim, "inputs:texture:file") {
            Some(sdf::Value::AssetPath(a)) => Some(a),
            _ => None,
        };
        let Some(file) = file.filter(|f| !f.is_empty()) else {
            if !self.builder.add_environment(tint) {
                self.warn(format!(
                    "{where_}: a second dome light, of constant colour, is ignored beside an environment map"
                ));
            }
            return;
        };
        let format = self
            .get_token(prim, "inputs:texture:format")
            .unwrap_or_else(|| "automatic".into());
        if !matches!(format.as_str(), "automatic" | "latlong") {
            self.warn(format!(
                "{where_}: texture:format '{format}' is not supported (only latlong); reading the map as latlong"
            ));
        }
        let Some(map) = self.environment_file(&file, &where_) else {
            return;
        };
        // The pole: along the stage's up axis unless `poleAxis` says Y, as usdview (USD
        // 25.05) and Blender's importer read both DomeLight and DomeLight_1; on a Z-up stage
        // the map's +Y goes to +Z and its centre column (+Z) to +X, which is also where
        // Blender's world puts them.
        let pole_axis = self
            .get_token(prim, "poleAxis")
            .unwrap_or_else(|| "scene".into());
        let up_is_z = self.stage_up_is_z();
        let pole_on_z = (up_is_z && pole_axis != "Y") || (!up_is_z && pole_axis == "Z");
        let pole = if pole_on_z {
            Mat3::from_cols(Vec3::Y, Vec3::Z, Vec3::X)
        } else {
            Mat3::IDENTITY
        };
        let (_, rotation, _) = world.to_scale_rotation_translation();
        let world_from_map = Mat3::from_quat(rotation.normalize()) * pole;
        if self.builder.scene_environment_is_set() {
            self.warn(format!(
                "{where_}: more than one dome light; the last one's map replaces the others"
            ));
        }
        let mut environment = Environment::from_map(map, tint, world_from_map, where_.clone());
        environment.camera_visible = self.camera_visibility(prim).unwrap_or(true);
        self.builder.set_environment(environment);
    }

    /// The lamp's camera visibility where the file says it (Karma's `renderlightgeo`,
    /// RenderMan's camera visibility primvar); `None` when it does not.
    fn camera_visibility(&self, prim: &sdf::Path) -> Option<bool> {
        [
            "karma:light:renderlightgeo",
            "primvars:ri:attributes:visibility:camera",
        ]
        .iter()
        .find_map(|name| self.get(prim, name).as_ref().and_then(as_bool))
    }

    /// UsdLux lights. Rect and disk lights are emitting surfaces, a sphere with a radius a
    /// sphere lamp; camera rays see none of them unless the file asks (see
    /// [`UsdLoader::camera_visibility`]). Radiance (area lights) or radiant intensity
    /// (points) is
    /// `intensity × 2^exposure × color`; `normalize` divides by the light's area, so that
    /// the power (π × radiance × area) stays `π × intensity` whatever its size — which is
    /// how Blender writes watts (intensity = W/π).
    pub(super) fn add_light(&mut self, prim: &sdf::Path, kind: &str, world: Mat4) {
        let where_ = prim.as_str().to_string();
        let normalize = self
            .get(prim, "inputs:normalize")
            .as_ref()
            .and_then(as_bool)
            .unwrap_or(false);
        let strength = self.light_strength(prim);
        if !strength.is_finite() || strength.min_element() < 0.0 {
            self.warn(format!(
                "{where_}: negative or non-finite light strength; skipped"
            ));
            return;
        }
        let transform = Affine3A::from_mat4(world);
        // World-space area scale of the light's local XY plane.
        let area_scale = transform
            .matrix3
            .x_axis
            .cross(transform.matrix3.y_axis)
            .length();
        // Lamps are not seen by camera rays (as in Cycles, Karma and Storm) unless the file
        // says they are.
        let camera_visible = self.camera_visibility(prim).unwrap_or(false);
        let emitter =
            |loader: &mut UsdLoader, positions: Vec<Vec3>, indices: Vec<[u32; 3]>, area: f32| {
                // The polygons inscribed in a disc or a sphere have a little less area than
                // the shape (`area`): scaled up, they emit the shape's power.
                let mesh_area: f32 = indices
                    .iter()
                    .map(|t| {
                        let [a, b, c] = t.map(|i| positions[i as usize]);
                        0.5 * (b - a).cross(c - a).length()
                    })
                    .sum();
                let radiance = if normalize {
                    strength / (area * area_scale).max(f32::MIN_POSITIVE)
                } else {
                    strength
                } * (area / mesh_area.max(f32::MIN_POSITIVE));
                let material = loader.builder.add_material(Material {
                    double_sided: false,
                    camera_visible,
                    lamp: true,
                    ..Material::diffuse(where_.clone(), Vec3::ZERO).with_emission(radiance)
                });
                let mesh = loader
                    .builder
                    .add_mesh(where_.clone(), positions, indices, material);
                loader.builder.add_instance(mesh, transform, where_.clone());
            };
        match kind {
            "RectLight" => {
                let w = 0.5 * self.get_f32(prim, "inputs:width").unwrap_or(1.0);
                let h = 0.5 * self.get_f32(prim, "inputs:height").unwrap_or(1.0);
                // In the XY plane, emitting towards −Z: wound clockwise seen from +Z.
                let positions = vec![
                    Vec3::new(-w, -h, 0.0),
                    Vec3::new(-w, h, 0.0),
                    Vec3::new(w, h, 0.0),
                    Vec3::new(w, -h, 0.0),
                ];
                emitter(self, positions, vec![[0, 1, 2], [0, 2, 3]], 4.0 * w * h);
            }
            "DiskLight" => {
                let r = self.get_f32(prim, "inputs:radius").unwrap_or(0.5);
                let mut positions = vec![Vec3::ZERO];
                positions.extend((0..DISK_SEGMENTS).map(|i| {
                    let a = -std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
                    Vec3::new(r * a.cos(), r * a.sin(), 0.0)
                }));
                let indices = (0..DISK_SEGMENTS)
                    .map(|i| [0, 1 + i, 1 + (i + 1) % DISK_SEGMENTS])
                    .collect();
                let area = std::f32::consts::PI * r * r;
                emitter(self, positions, indices, area);
            }
            "SphereLight" => {
                let local_radius = self.get_f32(prim, "inputs:radius").unwrap_or(0.5);
                let r = local_radius * area_scale.sqrt();
                let as_point =
                    self.get(prim, "treatAsPoint").as_ref().and_then(as_bool) == Some(true);
                let position = transform.transform_point3(Vec3::ZERO);
                // The ShapingAPI cone, as glTF's inner and outer angles.
                let cone = match self.get_f32(prim, "inputs:shaping:cone:angle") {
                    Some(angle) if angle < 180.0 => {
                        let softness = self
                            .get_f32(prim, "inputs:shaping:cone:softness")
                            .unwrap_or(0.0)
                            .clamp(0.0, 1.0);
                        let outer = angle.to_radians().min(std::f32::consts::FRAC_PI_2);
                        let direction =
                            transform.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                        Some((direction, (outer * (1.0 - softness)).cos(), outer.cos()))
                    }
                    _ => None,
                };
                let kind = if !as_point && r > 0.0 {
                    // A real sphere of radiance L, as Cycles renders a lamp with a radius;
                    // normalized, L = intensity / 4πr².
                    let radiance = if normalize {
                        strength / (4.0 * std::f32::consts::PI * r * r)
                    } else {
                        strength
                    };
                    LightKind::Sphere {
                        position,
                        radius: r,
                        radiance,
                        spot: cone,
                        camera_visible,
                        // Blender turns Soft Falloff on for every new lamp and its USD
                        // export does not say; other writers mean a ball.
                        soft: self.soft_falloff && self.from_blender,
                    }
                } else {
                    // A point: a sphere of radiance L sends L·πr² per steradian; normalized,
                    // intensity / 4.
                    let intensity = if normalize || r == 0.0 {
                        strength / 4.0
                    } else {
                        strength * std::f32::consts::PI * r * r
                    };
                    match cone {
                        Some((direction, cos_inner, cos_outer)) => LightKind::Spot {
                            position,
                            direction,
                            intensity,
                            cos_inner,
                            cos_outer,
                            range: None,
                        },
                        None => LightKind::Point {
                            position,
                            intensity,
                            range: None,
                        },
                    }
                };
                self.builder.add_light(Light {
                    name: where_.clone(),
                    kind,
                    source: where_,
                });
            }
            "DistantLight" => {
                let direction = transform.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                // Irradiance is intensity × 2^exposure × colour, except from Blender, whose
                // exporter writes a sun of S W/m² as intensity S/4 (and reads it back × 4).
                let irradiance = if self.from_blender {
                    4.0 * strength
                } else {
                    strength
                };
                self.builder.add_light(Light {
                    name: where_.clone(),
                    kind: LightKind::Directional {
                        direction,
                        irradiance,
                    },
                    source: where_,
                });
            }
            _ => {}
        }
    }
}

/// The colour of a blackbody at `kelvin` (clamped to 1667–25000 K) relative to one at
/// 6500 K, in linear sRGB: the Planckian locus approximation of Kim et al. (2002) gives its
/// chromaticity, the sRGB matrix (IEC 61966-2-1) its colour at unit luminance.
fn blackbody_tint(kelvin: f32) -> Vec3 {
    pub(super) fn rgb(kelvin: f64) -> Vec3 {
        let t = kelvin.clamp(1667.0, 25000.0);
        let (t2, t3) = (t * t, t * t * t);
        let x = if t <= 4000.0 {
            -0.2661239e9 / t3 - 0.2343589e6 / t2 + 0.8776956e3 / t + 0.179910
        } else {
            -3.0258469e9 / t3 + 2.1070379e6 / t2 + 0.2226347e3 / t + 0.240390
        };
        let y = if t <= 2222.0 {
            -1.1063814 * x * x * x - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
        } else if t <= 4000.0 {
            -0.9549476 * x * x * x - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
        } else {
            3.0817580 * x * x * x - 5.87338670 * x * x + 3.75112997 * x - 0.37001483
        };
        let (cx, cy, cz) = (x / y, 1.0, (1.0 - x - y) / y);
        Vec3::new(
            (3.2404542 * cx - 1.5371385 * cy - 0.4985314 * cz) as f32,
            (-0.9692660 * cx + 1.8760108 * cy + 0.0415560 * cz) as f32,
            (0.0556434 * cx - 0.2040259 * cy + 1.0572252 * cz) as f32,
        )
        .max(Vec3::ZERO)
    }
    if !kelvin.is_finite() {
        return Vec3::ONE;
    }
    rgb(kelvin as f64) / rgb(6500.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    pub(super) fn colour_temperature_is_warm_below_and_cool_above_6500_kelvin() {
        assert!((blackbody_tint(6500.0) - Vec3::ONE).abs().max_element() < 1e-6);
        let candle = blackbody_tint(2000.0);
        assert!(candle.x > 1.0 && candle.z < 0.3 * candle.x, "{candle}");
        let sky = blackbody_tint(12000.0);
        assert!(sky.z > sky.x, "{sky}");
    }
}
