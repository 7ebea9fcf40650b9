//! Light from infinitely far away: a constant colour or a latitude–longitude radiance map
//! (an HDR environment), placed by a rotation.
//!
//! A map is stored as its file has it and read in the OpenEXR latitude–longitude convention
//! (the one USD's `DomeLight` uses): in the map's own frame +Y is up; longitude 0 points to
//! +Z and π/2 to +X; the image's left column is longitude +π, its top row latitude +π/2.
//! [`Environment::world_from_map`] places that frame in the world.

use glam::{Mat3, Vec2, Vec3};

/// A latitude–longitude image of linear radiance, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    /// Name for messages (the file).
    pub name: String,
    /// Width in texels (longitude).
    pub width: u32,
    /// Height in texels (latitude).
    pub height: u32,
    /// Linear RGB radiance, `width × height`.
    pub texels: Vec<[f32; 3]>,
}

/// The radiance arriving from every direction no geometry covers.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Multiplies the map (strength × colour), or is the radiance itself without a map.
    pub tint: Vec3,
    /// The map, if the environment is not a constant colour.
    pub map: Option<EnvironmentMap>,
    /// Rotation from the map's frame (above) to the world.
    pub world_from_map: Mat3,
    /// When false, camera rays that leave the scene see black (alpha 0) while the
    /// environment still lights the scene.
    pub camera_visible: bool,
    /// Where it came from, for messages.
    pub source: String,
}

impl Environment {
    /// Constant radiance from every direction.
    pub fn constant(radiance: Vec3, source: impl Into<String>) -> Environment {
        Environment {
            tint: radiance,
            map: None,
            world_from_map: Mat3::IDENTITY,
            camera_visible: true,
            source: source.into(),
        }
    }

    /// A map seen through `world_from_map`, scaled by `tint`.
    pub fn from_map(
        map: EnvironmentMap,
        tint: Vec3,
        world_from_map: Mat3,
        source: impl Into<String>,
    ) -> Environment {
        Environment {
            tint,
            map: Some(map),
            world_from_map,
            camera_visible: true,
            source: source.into(),
        }
    }

    /// The neutral studio light scenes without any light are shown under, as model viewers
    /// show a downloaded model: a grey sky brightening from 0.5 at the horizon to 1 at the
    /// zenith over a 0.3 floor, and a soft key light (a 15° disc of radiance 6) high in front
    /// and to the left of the default camera's view, so shapes read from their shading. In
    /// gridtrace's Y-up world; white, so colours are the materials' own.
    pub fn studio() -> Environment {
        let (width, height) = (256u32, 128u32);
        let key = Vec3::new(-0.45, 0.75, 0.5).normalize();
        let key_cos = 15f32.to_radians().cos();
        let texels = (0..width * height)
            .map(|i| {
                let uv = Vec2::new(
                    ((i % width) as f32 + 0.5) / width as f32,
                    ((i / width) as f32 + 0.5) / height as f32,
                );
                let d = map_direction(uv);
                let sky = 0.5 + 0.5 * d.y.max(0.0);
                let horizon = smoothstep(-0.05, 0.05, d.y);
                let ambient = 0.3 + (sky - 0.3) * horizon;
                // The disc's edge softened over a degree or so.
                let in_key = smoothstep(key_cos - 0.003, key_cos + 0.003, d.dot(key));
                [ambient + 6.0 * in_key; 3]
            })
            .collect();
        let map = EnvironmentMap {
            name: "studio".into(),
            width,
            height,
            texels,
        };
        Environment::from_map(map, Vec3::ONE, Mat3::IDENTITY, "default studio environment")
    }

    /// True when it sends no light at all.
    pub fn is_black(&self) -> bool {
        self.tint.max_element() <= 0.0
            || self
                .map
                .as_ref()
                .is_some_and(|m| m.texels.iter().all(|t| t.iter().all(|&c| c <= 0.0)))
    }

    /// Mean radiance over the sphere of directions (solid-angle weighted).
    pub fn mean_radiance(&self) -> Vec3 {
        let Some(map) = &self.map else {
            return self.tint;
        };
        let mut sum = glam::DVec3::ZERO;
        let mut weight = 0.0f64;
        for y in 0..map.height {
            // A row's solid angle is proportional to the cosine of its latitude.
            let latitude = (0.5 - (y as f64 + 0.5) / map.height as f64) * std::f64::consts::PI;
            let w = latitude.cos();
            for x in 0..map.width {
                sum += w * map.texel(x, y).as_dvec3();
            }
            weight += w * map.width as f64;
        }
        self.tint * (sum / weight.max(f64::MIN_POSITIVE)).as_vec3()
    }

    /// Power (W), mean over channels, that reaches the disc of the sphere of radius
    /// `scene_radius` around the scene from one side: π·r² × π × mean radiance. Light
    /// selection weighs it against the other lights with this.
    pub fn power(&self, scene_radius: f32) -> f32 {
        let r = scene_radius.max(1e-3);
        std::f32::consts::PI * std::f32::consts::PI * r * r * self.mean_radiance().element_sum()
            / 3.0
    }

    /// Radiance arriving along world direction `-direction` (that is, seen looking along
    /// unit vector `direction`), the map filtered bilinearly.
    pub fn radiance(&self, direction: Vec3) -> Vec3 {
        match &self.map {
            None => self.tint,
            Some(map) => {
                let uv = map_uv(self.world_from_map.transpose() * direction);
                self.tint * map.bilinear(uv)
            }
        }
    }
}

/// 0 below `a`, 1 above `b`, a cubic step between.
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Image coordinates in [0, 1]² (u right, v down) of map-frame unit direction `d`, in the
/// OpenEXR convention: u = ½ − longitude/2π with longitude = atan2(x, z), v = ½ − latitude/π.
pub fn map_uv(d: Vec3) -> Vec2 {
    let longitude = d.x.atan2(d.z);
    let latitude = d.y.clamp(-1.0, 1.0).asin();
    Vec2::new(
        0.5 - longitude * (0.5 * std::f32::consts::FRAC_1_PI),
        0.5 - latitude * std::f32::consts::FRAC_1_PI,
    )
}

/// The map-frame unit direction at image coordinates `uv`: the inverse of [`map_uv`].
pub fn map_direction(uv: Vec2) -> Vec3 {
    let longitude = (0.5 - uv.x) * std::f32::consts::TAU;
    let latitude = (0.5 - uv.y) * std::f32::consts::PI;
    let (sin_lat, cos_lat) = latitude.sin_cos();
    let (sin_lon, cos_lon) = longitude.sin_cos();
    Vec3::new(cos_lat * sin_lon, sin_lat, cos_lat * cos_lon)
}

impl EnvironmentMap {
    /// The texel at column `x`, row `y`.
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        Vec3::from(self.texels[(y * self.width + x) as usize])
    }

    /// Bilinear lookup at `uv`: longitude wraps around, latitude holds the edge rows.
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        if self.texels.is_empty() {
            return Vec3::ZERO;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let fx = uv.x * self.width as f32 - 0.5;
        let fy = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let column = |x: i64| x.rem_euclid(w) as u32;
        let row = |y: i64| y.clamp(0, h - 1) as u32;
        let (xa, xb) = (column(x0 as i64), column(x0 as i64 + 1));
        let (ya, yb) = (row(y0 as i64), row(y0 as i64 + 1));
        let top = self.texel(xa, ya).lerp(self.texel(xb, ya), tx);
        let bottom = self.texel(xa, yb).lerp(self.texel(xb, yb), tx);
        top.lerp(bottom, ty)
    }
}

/// The rotation that shows a latitude–longitude map as Blender's world (and three.js and
/// most viewers) does in gridtrace's Y-up world — the image's centre column towards +X, u
/// growing towards +Z — turned by `degrees` about the up axis (right-handed: positive turns
/// it counter-clockwise seen from above, +X towards −Z).
pub fn blender_world_rotation(degrees: f32) -> Mat3 {
    // The OpenEXR frame puts the centre column towards +Z; a quarter turn about +Y takes it
    // to +X (rotation about Y by a moves azimuth atan2(z, x) by −a).
    Mat3::from_rotation_y(degrees.to_radians()) * Mat3::from_rotation_y(std::f32::consts::FRAC_PI_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_coordinates_follow_the_openexr_convention_and_invert() {
        // Longitude 0 at +Z is the centre column, π/2 (+X) left of it, the top row is +Y.
        assert!((map_uv(Vec3::Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((map_uv(Vec3::X) - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!(map_uv(Vec3::Y).y.abs() < 1e-6);
        assert!((map_uv(Vec3::NEG_Y).y - 1.0).abs() < 1e-6);
        for uv in [
            Vec2::new(0.1, 0.2),
            Vec2::new(0.7, 0.9),
            Vec2::new(0.5, 0.5),
        ] {
            let back = map_uv(map_direction(uv));
            assert!((back - uv).length() < 1e-5, "{uv} -> {back}");
        }
    }

    #[test]
    fn blender_rotation_puts_the_centre_column_at_plus_x_and_u_towards_plus_z() {
        let m = blender_world_rotation(0.0);
        let uv = |world: Vec3| map_uv(m.transpose() * world);
        assert!((uv(Vec3::X) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((uv(Vec3::Z).x - 0.75).abs() < 1e-6);
        // Turning the world by 90° (Blender's +Z, gridtrace's +Y) brings the centre to −Z.
        let turned = blender_world_rotation(90.0);
        assert!((map_uv(turned.transpose() * Vec3::NEG_Z).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn bilinear_wraps_in_longitude_and_clamps_in_latitude() {
        let map = EnvironmentMap {
            name: "test".into(),
            width: 2,
            height: 1,
            texels: vec![[0.0; 3], [1.0; 3]],
        };
        // Halfway between the last column and the first, across the seam.
        assert!((map.bilinear(Vec2::new(1.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((map.bilinear(Vec2::new(0.75, 0.0)).x - 1.0).abs() < 1e-6);
    }
}
