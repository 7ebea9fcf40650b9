//! Emissive triangles as lights: each triangle of an emissive material, placed in world
//! space (or placed at each path's time, for a moving instance), with its power, its bounds
//! for the light tree, and a point drawn on it — uniform over the solid angle it subtends
//! where that is well conditioned ([`spherical`]), else uniform over its area.

use std::collections::HashMap;

use glam::{Affine3A, Vec2, Vec3};

use super::sample::LightSample;
use super::spherical;
use super::tree::{Cone, LightBounds, TreeInput};
use crate::geometry::Aabb;
use crate::geometry::{interpolate_with_error, transform_points_with_error};
use crate::render::sampling::uniform_triangle;
use crate::scene::{ColorSpace, Motion, Scene, TextureRef, TimeSlice};

/// One emitting triangle in world space.
#[derive(Clone, Copy, Debug)]
struct EmissiveTriangle {
    /// Where it is (at the frame's instant, for a moving one).
    placed: PlacedTriangle,
    /// For a moving instance's triangle: its object-space corners and the index of the
    /// instance's motion in [`EmissiveTriangles::motions`], to place it at each path's
    /// time.
    moving: Option<([Vec3; 3], u32)>,
    /// For a time slice of a deforming mesh: when it is there.
    slice: Option<TimeSlice>,
    radiance: Vec3,
    /// The material's emitted power per unit area (W/m²).
    exitance: f32,
    double_sided: bool,
    /// The emissive texture and the triangle's coordinates in it, if the emission varies.
    texture: Option<(TextureRef, [Vec2; 3])>,
}

/// A triangle placed in world space.
#[derive(Clone, Copy, Debug)]
struct PlacedTriangle {
    /// World-space corners with the rounding-error bound the transform added to each.
    corners: [(Vec3, Vec3); 3],
    /// Unit geometric normal, on the side the winding calls front.
    normal: Vec3,
    area: f32,
}

impl PlacedTriangle {
    /// The object-space triangle `object` placed by `m`. Mirroring transforms flip the
    /// winding; the normal follows the object-space front face, which is what the
    /// renderer's hit normal uses too.
    fn new(m: &Affine3A, object: [Vec3; 3]) -> PlacedTriangle {
        let corners = transform_points_with_error(m, object);
        let [p0, p1, p2] = corners.map(|c| c.0);
        let cross = (p1 - p0).cross(p2 - p0);
        let area = 0.5 * cross.length();
        let usable = area.is_finite() && area > 0.0;
        let sign = if m.matrix3.determinant() < 0.0 {
            -1.0
        } else {
            1.0
        };
        PlacedTriangle {
            corners,
            normal: if usable {
                sign * cross / (2.0 * area)
            } else {
                Vec3::Z
            },
            area: if usable { area } else { 0.0 },
        }
    }

    fn bounds(&self) -> Aabb {
        self.corners
            .iter()
            .fold(Aabb::EMPTY, |b, c| b.union(Aabb { min: c.0, max: c.0 }))
    }
}

/// Every emissive triangle of a scene's instances, in instance order.
#[derive(Clone, Debug, Default)]
pub struct EmissiveTriangles {
    triangles: Vec<EmissiveTriangle>,
    /// For each instance, the index of its mesh's first triangle in `triangles`, if emissive.
    first_of_instance: Vec<Option<u32>>,
    /// The motions of moving emissive instances.
    motions: Vec<Motion>,
}

impl EmissiveTriangles {
    /// The triangles of every instance of an emissive material.
    pub fn collect(scene: &Scene) -> EmissiveTriangles {
        let mut set = EmissiveTriangles::default();
        for inst in &scene.instances {
            let mesh = &scene.meshes[inst.mesh];
            let material = &scene.materials[mesh.material];
            if !material.is_emissive() {
                set.first_of_instance.push(None);
                continue;
            }
            set.first_of_instance.push(Some(set.triangles.len() as u32));
            let m = inst.world_from_object;
            let texture = material.textures.emissive;
            let motion = inst.motion.clone().map(|motion| {
                set.motions.push(motion);
                set.motions.len() as u32 - 1
            });
            for &[a, b, c] in &mesh.indices {
                let object = [a, b, c].map(|i| mesh.positions[i as usize]);
                set.triangles.push(EmissiveTriangle {
                    placed: PlacedTriangle::new(&m, object),
                    moving: motion.map(|k| (object, k)),
                    slice: inst.slice,
                    radiance: material.emission,
                    exitance: material.exitance(),
                    double_sided: material.double_sided,
                    texture: texture
                        .map(|r| (r, [a, b, c].map(|v| mesh.uv(r.texcoord, v as usize)))),
                });
            }
        }
        set
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when no triangle emits.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Emitted power (W, mean over channels) of every triangle, in order: area ×
    /// exitance, a textured one's scaled by its texture's mean.
    pub fn powers(&self, scene: &Scene) -> Vec<f32> {
        let mut texture_means = HashMap::new();
        let mut texture_mean = |r: TextureRef| {
            *texture_means.entry(r.texture).or_insert_with(|| {
                let mean = scene.textures[r.texture].mean(ColorSpace::Srgb);
                mean.truncate().element_sum() / 3.0
            })
        };
        self.triangles
            .iter()
            .map(|t| {
                let scale = t.texture.map_or(1.0, |(r, _)| texture_mean(r));
                t.placed.area * t.exitance * scale
            })
            .collect()
    }

    /// Where triangle `index` can send light from and to and how strongly, for the light
    /// tree: a Lambertian emitter's intensity along its normal is radiance × area, and its
    /// power π × radiance × area on each emitting side. A moving triangle is bounded over
    /// the whole shutter, with any normal.
    pub fn tree_input(&self, index: usize, power: f32) -> TreeInput {
        let t = &self.triangles[index];
        let sides = if t.double_sided { 2.0 } else { 1.0 };
        let surface = |bounds, normals, two_sided| LightBounds {
            bounds,
            intensity: power / (std::f32::consts::PI * sides),
            normals,
            cos_emission: 0.0,
            two_sided,
        };
        TreeInput::Placed(match t.moving {
            None => surface(
                t.placed.bounds(),
                Cone {
                    axis: t.placed.normal,
                    cos_angle: 1.0,
                },
                t.double_sided,
            ),
            Some((object, k)) => surface(
                self.motions[k as usize]
                    .keys()
                    .iter()
                    .fold(Aabb::EMPTY, |b, key| {
                        b.union(PlacedTriangle::new(key, object).bounds())
                    }),
                Cone::ALL,
                true,
            ),
        })
    }

    /// A point on triangle `index`, chosen with probability `pmf`, as seen from `p` at
    /// shutter time `time`: uniform over the solid angle it subtends at `p` where that is
    /// well conditioned, else uniform over its area, the density turned into solid angle by
    /// distance² / |cos θ_light|.
    pub fn sample(
        &self,
        scene: &Scene,
        index: usize,
        pmf: f32,
        p: Vec3,
        time: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let tri = &self.triangles[index];
        let placed = self.placed_at(tri, time)?;
        if placed.area == 0.0 {
            return None;
        }
        let corners = placed.corners.map(|c| c.0);
        let by_solid_angle = spherical::by_solid_angle(p, corners);
        let b = match by_solid_angle {
            Some((directions, omega)) => {
                spherical::sample_from(p, corners, directions, omega, u)?.1
            }
            None => uniform_triangle(u),
        };
        let (point, point_error) =
            interpolate_with_error(placed.corners, [1.0 - b.x - b.y, b.x, b.y]);
        let to_light = point - p;
        let distance_sq = to_light.length_squared();
        let distance = distance_sq.sqrt();
        if distance == 0.0 {
            return None;
        }
        let wi = to_light / distance;
        let cos_light = placed.normal.dot(-wi);
        if cos_light == 0.0 {
            return None;
        }
        let pdf = match by_solid_angle {
            Some((_, omega)) => pmf / omega as f32,
            None => pmf / placed.area * distance_sq / cos_light.abs(),
        };
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
            normal: placed.normal,
            wi,
            distance,
            radiance,
            pdf,
            is_delta: false,
        })
    }

    /// The index of triangle `triangle` of instance `instance`, if that instance emits.
    pub fn index_of(&self, instance: u32, triangle: u32) -> Option<usize> {
        let first = self.first_of_instance[instance as usize]?;
        Some((first + triangle) as usize)
    }

    /// The solid-angle density with which [`EmissiveTriangles::sample`] at `origin`, having
    /// chosen triangle `index` with probability `pmf()`, would draw its point at `distance`
    /// and light cosine `cos_light`, at shutter time `time`. `pmf` (a walk of the light
    /// tree) is asked only when the triangle can have been sampled at all.
    pub fn pdf(
        &self,
        index: usize,
        pmf: impl FnOnce() -> f32,
        time: f32,
        origin: Vec3,
        distance: f32,
        cos_light: f32,
    ) -> f32 {
        let Some(placed) = self.placed_at(&self.triangles[index], time) else {
            return 0.0;
        };
        if placed.area == 0.0 || cos_light == 0.0 {
            return 0.0;
        }
        let pmf = pmf();
        if pmf == 0.0 {
            return 0.0;
        }
        if let Some((_, omega)) = spherical::by_solid_angle(origin, placed.corners.map(|c| c.0)) {
            return pmf / omega as f32;
        }
        pmf / placed.area * distance * distance / cos_light.abs()
    }

    /// Where `tri` is at shutter time `time`, or `None` when it is not there then (a time
    /// slice of a deforming mesh). A slice's triangles keep their share of the light
    /// distribution at every time; samples drawn from them outside it bring nothing, which
    /// wastes them but keeps the estimate unbiased.
    fn placed_at(&self, tri: &EmissiveTriangle, time: f32) -> Option<PlacedTriangle> {
        if tri.slice.is_some_and(|s| !s.contains(time)) {
            return None;
        }
        Some(match tri.moving {
            None => tri.placed,
            Some((object, k)) => PlacedTriangle::new(&self.motions[k as usize].at(time), object),
        })
    }

    /// Power (W, mean over channels) each material emits over all its instances, with
    /// constant emission (textures not counted), for reports.
    pub fn power_by_material(&self, scene: &Scene) -> Vec<f32> {
        let mut power = vec![0.0f32; scene.materials.len()];
        for (instance, first) in self.first_of_instance.iter().enumerate() {
            let Some(first) = first else { continue };
            let mesh = &scene.meshes[scene.instances[instance].mesh];
            let triangles = &self.triangles[*first as usize..][..mesh.indices.len()];
            let area: f32 = triangles.iter().map(|t| t.placed.area).sum();
            power[mesh.material] += area * scene.materials[mesh.material].exitance();
        }
        power
    }
}
