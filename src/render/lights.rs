//! The lights next-event estimation samples: every triangle of an emissive material, in
//! world space, and every punctual light, each chosen in proportion to its emitted power.

use std::f32::consts::PI;

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::sampling::{Distribution1d, uniform_sphere, uniform_triangle};
use super::shading::vertex_uv;
use super::surface::{interpolate_with_error, transform_point_with_error};
use crate::scene::{ColorSpace, LightKind, Scene, TextureRef};

/// One emitting triangle in world space.
#[derive(Clone, Copy, Debug)]
struct EmissiveTriangle {
    /// World-space corners with the rounding-error bound the transform added to each.
    corners: [(Vec3, Vec3); 3],
    /// Unit geometric normal, on the side the winding calls front.
    normal: Vec3,
    area: f32,
    radiance: Vec3,
    double_sided: bool,
    /// The emissive texture and the triangle's coordinates in it, if the emission varies.
    texture: Option<(TextureRef, [Vec2; 3])>,
}

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

/// All emissive triangles and punctual lights of a scene, and the distributions used to
/// pick them.
pub struct LightSet {
    triangles: Vec<EmissiveTriangle>,
    punctual: Vec<LightKind>,
    /// Over the triangles, then the punctual lights.
    distribution: Distribution1d,
    /// Over the punctual lights alone, for estimators that find area lights by hitting them.
    punctual_distribution: Distribution1d,
    /// Radius of a sphere around the scene's geometry: directional lights are sampled from
    /// beyond it, and their power is what crosses its disc.
    scene_radius: f32,
    scene_center: Vec3,
    /// Constant radiance from directions that miss the scene.
    environment: Vec3,
    /// For each instance, the index of its mesh's first triangle in `triangles`, if emissive.
    first_of_instance: Vec<Option<u32>>,
}

impl LightSet {
    /// Collects the emissive triangles of every instance.
    pub fn build(scene: &Scene) -> LightSet {
        let mut triangles = Vec::new();
        let mut first_of_instance = Vec::with_capacity(scene.instances.len());
        for inst in &scene.instances {
            let mesh = &scene.meshes[inst.mesh];
            let material = &scene.materials[mesh.material];
            if !material.is_emissive() {
                first_of_instance.push(None);
                continue;
            }
            first_of_instance.push(Some(triangles.len() as u32));
            let m = inst.world_from_object;
            let texture = material.textures.emissive;
            for &[a, b, c] in &mesh.indices {
                let corners =
                    [a, b, c].map(|i| transform_point_with_error(&m, mesh.positions[i as usize]));
                let [p0, p1, p2] = corners.map(|c| c.0);
                let (e1, e2) = (p1 - p0, p2 - p0);
                let cross = e1.cross(e2);
                let area = 0.5 * cross.length();
                let usable = area.is_finite() && area > 0.0;
                // Mirroring transforms flip the winding; the normal follows the object-space
                // front face, which is what the renderer's hit normal uses too.
                let sign = if m.matrix3.determinant() < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                triangles.push(EmissiveTriangle {
                    corners,
                    normal: if usable {
                        sign * cross / (2.0 * area)
                    } else {
                        Vec3::Z
                    },
                    area: if usable { area } else { 0.0 },
                    radiance: material.emission,
                    double_sided: material.double_sided,
                    texture: texture.map(|r| {
                        (
                            r,
                            [a, b, c].map(|v| vertex_uv(mesh, r.texcoord, v as usize)),
                        )
                    }),
                });
            }
        }
        let bounds = scene.bounds();
        let (scene_center, scene_radius) = if bounds.is_empty() {
            (Vec3::ZERO, 0.0)
        } else {
            (bounds.center(), 0.5 * bounds.extent().length())
        };
        let punctual: Vec<LightKind> = scene.lights.iter().map(|l| l.kind).collect();
        let punctual_weights: Vec<f32> = punctual
            .iter()
            .map(|l| punctual_power(l, scene_radius))
            .collect();
        // A constant environment sends π·L per unit area onto the scene's bounding disc from
        // each side it is seen; what matters is that it competes fairly with the others.
        let environment = scene.environment;
        let environment_weight = if environment.max_element() > 0.0 {
            let radius = scene_radius.max(1e-3);
            PI * PI * radius * radius * environment.element_sum() / 3.0
        } else {
            0.0
        };
        // A textured emitter counts with its texture's mean.
        let mut texture_means = HashMap::new();
        let weights = triangles
            .iter()
            .map(|t| {
                let sides = if t.double_sided { 2.0 } else { 1.0 };
                let scale = t.texture.map_or(Vec3::ONE, |(r, _)| {
                    *texture_means.entry(r.texture).or_insert_with(|| {
                        scene.textures[r.texture].mean(ColorSpace::Srgb).truncate()
                    })
                });
                t.area * sides * PI * (t.radiance * scale).element_sum() / 3.0
            })
            .chain(punctual_weights.iter().copied())
            .chain(std::iter::once(environment_weight))
            .collect();
        LightSet {
            triangles,
            punctual,
            distribution: Distribution1d::new(weights),
            punctual_distribution: Distribution1d::new(punctual_weights),
            scene_radius,
            scene_center,
            environment,
            first_of_instance,
        }
    }

    /// True when nothing emits.
    pub fn is_empty(&self) -> bool {
        self.distribution.total() <= 0.0
    }

    /// Number of emissive triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Number of punctual lights.
    pub fn punctual_len(&self) -> usize {
        self.punctual.len()
    }

    /// Total emitted power (W), summed over channels' mean.
    pub fn total_power(&self) -> f64 {
        self.distribution.total()
    }

    /// Draws a point on a light for shading point `p`: a triangle by power, then a uniform
    /// point on it; the area density is turned into solid angle by distance²/|cos θ_light|.
    pub fn sample(&self, scene: &Scene, p: Vec3, u_light: f32, u: Vec2) -> Option<LightSample> {
        let (index, pmf) = self.distribution.sample(u_light)?;
        let Some(tri) = self.triangles.get(index) else {
            let punctual = index - self.triangles.len();
            if punctual == self.punctual.len() {
                return self.sample_environment(pmf, p, u);
            }
            return self.sample_punctual_light(punctual, pmf, p);
        };
        let b = uniform_triangle(u);
        let (point, point_error) = interpolate_with_error(tri.corners, [1.0 - b.x - b.y, b.x, b.y]);
        let to_light = point - p;
        let distance_sq = to_light.length_squared();
        let distance = distance_sq.sqrt();
        if distance == 0.0 {
            return None;
        }
        let wi = to_light / distance;
        let cos_light = tri.normal.dot(-wi);
        if cos_light == 0.0 {
            return None;
        }
        let pdf = pmf / tri.area * distance_sq / cos_light.abs();
        let mut radiance = if tri.double_sided || cos_light > 0.0 {
            tri.radiance
        } else {
            Vec3::ZERO
        };
        if let Some((r, uvs)) = &tri.texture {
            let uv = (1.0 - b.x - b.y) * uvs[0] + b.x * uvs[1] + b.y * uvs[2];
            radiance *= scene.textures[r.texture]
                .sample(r, uv, ColorSpace::Srgb)
                .truncate();
        }
        Some(LightSample {
            point,
            point_error,
            normal: tri.normal,
            wi,
            distance,
            radiance,
            pdf,
            is_delta: false,
        })
    }

    /// The constant environment: a uniform direction on the sphere, from beyond the scene.
    fn sample_environment(&self, pmf: f32, p: Vec3, u: Vec2) -> Option<LightSample> {
        let wi = uniform_sphere(u);
        let far = 2.0 * self.scene_radius + p.distance(self.scene_center) + 1.0;
        Some(LightSample {
            point: p + far * wi,
            point_error: Vec3::ZERO,
            normal: -wi,
            wi,
            distance: far,
            radiance: self.environment,
            pdf: pmf / (4.0 * PI),
            is_delta: false,
        })
    }

    /// Radiance of the environment along a ray that left the scene, and the solid-angle
    /// density with which [`LightSet::sample`] would have picked that direction.
    pub fn environment(&self) -> (Vec3, f32) {
        let index = self.triangles.len() + self.punctual.len();
        (self.environment, self.distribution.pmf(index) / (4.0 * PI))
    }

    /// Draws a punctual light alone, by power, for shading point `p`.
    pub fn sample_punctual(&self, p: Vec3, u_light: f32) -> Option<LightSample> {
        let (index, pmf) = self.punctual_distribution.sample(u_light)?;
        self.sample_punctual_light(index, pmf, p)
    }

    /// The contribution of punctual light `index`, picked with probability `pmf`, at `p`.
    fn sample_punctual_light(&self, index: usize, pmf: f32, p: Vec3) -> Option<LightSample> {
        let light = &self.punctual[index];
        let (point, radiance) = match *light {
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
            } => {
                // From beyond the scene, so the shadow ray crosses all of it.
                let far = 2.0 * self.scene_radius + p.distance(self.scene_center) + 1.0;
                (p - far * direction, irradiance)
            }
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

    /// The solid-angle density with which [`LightSet::sample`] would pick the point of
    /// triangle `triangle` of instance `instance` at `distance` and light cosine `cos_light`.
    pub fn pdf(&self, instance: u32, triangle: u32, distance: f32, cos_light: f32) -> f32 {
        let Some(first) = self.first_of_instance[instance as usize] else {
            return 0.0;
        };
        let index = (first + triangle) as usize;
        let tri = &self.triangles[index];
        if tri.area == 0.0 || cos_light == 0.0 {
            return 0.0;
        }
        self.distribution.pmf(index) / tri.area * distance * distance / cos_light.abs()
    }
}

/// Emitted power of a punctual light, mean over channels (W), for choosing lights: a spot
/// counts its cone up to halfway through the falloff; a directional light, what crosses the
/// scene's bounding disc.
fn punctual_power(light: &LightKind, scene_radius: f32) -> f32 {
    match *light {
        LightKind::Point { intensity, .. } => 4.0 * PI * intensity.element_sum() / 3.0,
        LightKind::Spot {
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => {
            let solid_angle = 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer));
            solid_angle * intensity.element_sum() / 3.0
        }
        LightKind::Directional { irradiance, .. } => {
            PI * scene_radius * scene_radius * irradiance.element_sum() / 3.0
        }
    }
}
