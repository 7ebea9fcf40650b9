//! Emissive triangles as lights: each triangle of an emissive material, placed in world
//! space (or placed at each path's time, for a moving instance), with its power, its bounds
//! for the light tree, and a point drawn on it — uniform over the solid angle it subtends
//! where that is well conditioned ([`spherical`]), else uniform over its area. Pairs of a
//! still, untextured mesh that make a rectangle are one light instead ([`quad`]).

use std::collections::HashMap;

use glam::{Affine3A, Vec2, Vec3};

use super::quad::{Density, EmissiveQuad};
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

impl EmissiveTriangle {
    /// The light sample at the point with barycentric weights `b` on `placed` (where this
    /// triangle is), drawn from `p` with `density` by a light chosen with probability `pmf`.
    fn sample_at(
        &self,
        scene: &Scene,
        placed: &PlacedTriangle,
        b: [f32; 3],
        p: Vec3,
        pmf: f32,
        density: Density,
    ) -> Option<LightSample> {
        let (point, point_error) = interpolate_with_error(placed.corners, b);
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
        let mut radiance = if self.double_sided || cos_light > 0.0 {
            self.radiance
        } else {
            Vec3::ZERO
        };
        if let Some((r, uvs)) = &self.texture {
            let uv = b[0] * uvs[0] + b[1] * uvs[1] + b[2] * uvs[2];
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
            pdf: density.pdf(pmf, distance_sq, cos_light),
            is_delta: false,
        })
    }
}

/// A triangle placed in world space.
#[derive(Clone, Copy, Debug)]
pub struct PlacedTriangle {
    /// World-space corners with the rounding-error bound the transform added to each.
    pub corners: [(Vec3, Vec3); 3],
    /// Unit geometric normal, on the side the winding calls front.
    pub normal: Vec3,
    pub area: f32,
}

impl PlacedTriangle {
    /// The object-space triangle `object` placed by `m`. Mirroring transforms flip the
    /// winding; the normal follows the object-space front face, which is what the
    /// renderer's hit normal uses too.
    pub fn new(m: &Affine3A, object: [Vec3; 3]) -> PlacedTriangle {
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

/// One light among the emissive triangles: a triangle alone or a rectangle of two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emitter {
    /// A triangle, by index into the set's triangles.
    Triangle(usize),
    /// A rectangle, by index into the set's quads.
    Quad(usize),
}

/// Every emissive triangle of a scene's instances, in instance order.
#[derive(Clone, Debug, Default)]
pub struct EmissiveTriangles {
    triangles: Vec<EmissiveTriangle>,
    /// The pairs of triangles that are one rectangular light.
    quads: Vec<EmissiveQuad>,
    /// For each triangle, the quad it belongs to.
    quad_of: Vec<Option<u32>>,
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
            let first = set.quad_of.len();
            set.quad_of.resize(set.triangles.len(), None);
            if motion.is_none() && inst.slice.is_none() && texture.is_none() {
                set.pair_quads(first);
            }
        }
        set
    }

    /// Makes quads of the rectangles that consecutive triangles from `first` on make.
    fn pair_quads(&mut self, first: usize) {
        let mut i = first;
        while i + 1 < self.triangles.len() {
            let placed = [&self.triangles[i].placed, &self.triangles[i + 1].placed];
            match EmissiveQuad::pair([i, i + 1], placed) {
                Some(quad) => {
                    let index = Some(self.quads.len() as u32);
                    (self.quad_of[i], self.quad_of[i + 1]) = (index, index);
                    self.quads.push(quad);
                    i += 2;
                }
                None => i += 1,
            }
        }
    }

    /// The lights the triangles make, in triangle order: each quad where its first
    /// triangle is, and every triangle of no quad.
    pub fn emitters(&self) -> Vec<Emitter> {
        (0..self.triangles.len())
            .filter_map(|i| match self.quad_of[i] {
                None => Some(Emitter::Triangle(i)),
                Some(q) if self.quads[q as usize].triangles[0] == i => {
                    Some(Emitter::Quad(q as usize))
                }
                Some(_) => None,
            })
            .collect()
    }

    /// For each triangle, the index in `emitters` (as [`EmissiveTriangles::emitters`] gave
    /// them) of the light it is part of.
    pub fn emitter_indices(&self, emitters: &[Emitter]) -> Vec<u32> {
        let mut index = vec![0; self.triangles.len()];
        for (k, &e) in emitters.iter().enumerate() {
            match e {
                Emitter::Triangle(i) => index[i] = k as u32,
                Emitter::Quad(q) => {
                    for i in self.quads[q].triangles {
                        index[i] = k as u32;
                    }
                }
            }
        }
        index
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when no triangle emits.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Emitted power (W, mean over channels) of each of `emitters`: area × exitance, a
    /// textured triangle's scaled by its texture's mean.
    pub fn powers(&self, scene: &Scene, emitters: &[Emitter]) -> Vec<f32> {
        let mut texture_means = HashMap::new();
        let mut texture_mean = |r: TextureRef| {
            *texture_means.entry(r.texture).or_insert_with(|| {
                let mean = scene.textures[r.texture].mean(ColorSpace::Srgb);
                mean.truncate().element_sum() / 3.0
            })
        };
        let mut power = |t: &EmissiveTriangle| {
            let scale = t.texture.map_or(1.0, |(r, _)| texture_mean(r));
            t.placed.area * t.exitance * scale
        };
        emitters
            .iter()
            .map(|&e| match e {
                Emitter::Triangle(i) => power(&self.triangles[i]),
                Emitter::Quad(q) => self.quads[q]
                    .triangles
                    .iter()
                    .map(|&i| power(&self.triangles[i]))
                    .sum(),
            })
            .collect()
    }

    /// Where `emitter` can send light from and to and how strongly, for the light tree: a
    /// Lambertian emitter's intensity along its normal is radiance × area, and its power
    /// π × radiance × area on each emitting side. A moving triangle is bounded over the
    /// whole shutter, with any normal; a quad by its two triangles.
    pub fn tree_input(&self, emitter: Emitter, power: f32) -> TreeInput {
        let index = match emitter {
            Emitter::Triangle(i) => i,
            Emitter::Quad(q) => self.quads[q].triangles[0],
        };
        let t = &self.triangles[index];
        let sides = if t.double_sided { 2.0 } else { 1.0 };
        let surface = |bounds, normals, two_sided| LightBounds {
            bounds,
            intensity: power / (std::f32::consts::PI * sides),
            normals,
            cos_emission: 0.0,
            two_sided,
        };
        if let Emitter::Quad(q) = emitter {
            let [a, b] = self.quads[q].triangles.map(|i| self.triangles[i].placed);
            let normals = Cone {
                axis: a.normal,
                cos_angle: a.normal.dot(b.normal).min(1.0),
            };
            return TreeInput::Placed(surface(
                a.bounds().union(b.bounds()),
                normals,
                t.double_sided,
            ));
        }
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

    /// A point on `emitter`, chosen with probability `pmf`, as seen from `p` at shutter
    /// time `time`: uniform over the solid angle it subtends at `p` where that is well
    /// conditioned, else uniform over its area, the density turned into solid angle by
    /// distance² / |cos θ_light|.
    pub fn sample(
        &self,
        scene: &Scene,
        emitter: Emitter,
        pmf: f32,
        p: Vec3,
        time: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let index = match emitter {
            Emitter::Triangle(i) => i,
            Emitter::Quad(q) => {
                let quad = &self.quads[q];
                let (half, weights, density) = quad.sample(p, u);
                let tri = &self.triangles[quad.triangles[half]];
                return tri.sample_at(scene, &tri.placed, weights, p, pmf, density);
            }
        };
        let tri = &self.triangles[index];
        let placed = self.placed_at(tri, time)?;
        if placed.area == 0.0 {
            return None;
        }
        let corners = placed.corners.map(|c| c.0);
        let (b, density) = match spherical::by_solid_angle(p, corners) {
            Some((directions, omega)) => (
                spherical::sample_from(p, corners, directions, omega, u)?.1,
                Density::SolidAngle(omega),
            ),
            None => (uniform_triangle(u), Density::Area(placed.area)),
        };
        tri.sample_at(scene, &placed, [1.0 - b.x - b.y, b.x, b.y], p, pmf, density)
    }

    /// The index of triangle `triangle` of instance `instance`, if that instance emits.
    pub fn index_of(&self, instance: u32, triangle: u32) -> Option<usize> {
        let first = self.first_of_instance[instance as usize]?;
        Some((first + triangle) as usize)
    }

    /// The solid-angle density with which [`EmissiveTriangles::sample`] at `origin`, having
    /// chosen the light of triangle `index` ([`EmissiveTriangles::emitter_of`]) with
    /// probability `pmf()`, would draw its point at `distance` and light cosine `cos_light`,
    /// at shutter time `time`. `pmf` (a walk of the light tree) is asked only when the
    /// triangle can have been sampled at all.
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
        let density = match self.quad_of[index] {
            Some(q) => self.quads[q as usize].density(origin),
            None => match spherical::by_solid_angle(origin, placed.corners.map(|c| c.0)) {
                Some((_, omega)) => Density::SolidAngle(omega),
                None => Density::Area(placed.area),
            },
        };
        density.pdf(pmf, distance * distance, cos_light)
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
