//! The lights next-event estimation samples — every triangle of an emissive material in
//! world space, every punctual light, the environment — chosen for each shading point by
//! the light tree ([`tree`]) from their intensity and bounds ([`Light`] names one of them;
//! each kind has its power, intensity, bounds and density here or beside its data, and
//! nowhere else).

mod environment;
mod sphere;
mod spherical;
mod tree;

use std::collections::HashMap;

use glam::{Affine3A, Vec2, Vec3};

pub use environment::EnvironmentLight;

use super::sampling::{Distribution1d, uniform_triangle};
use super::shading::vertex_uv;
use super::surface::{interpolate_with_error, transform_point_with_error};
use crate::scene::{Aabb, ColorSpace, LightKind, Motion, Scene, TextureRef, TimeSlice};
use tree::{Cone, Distant, LightBounds, LightTree, TreeInput};

/// One emitting triangle in world space.
#[derive(Clone, Copy, Debug)]
struct EmissiveTriangle {
    /// Where it is (at the frame's instant, for a moving one).
    placed: PlacedTriangle,
    /// For a moving instance's triangle: its object-space corners and the index of the
    /// instance's motion in [`LightSet::motions`], to place it at each path's time.
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
        let corners = object.map(|p| transform_point_with_error(m, p));
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

/// One light of a [`LightSet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Light {
    /// An emissive triangle, by index into the set's triangles.
    Triangle(usize),
    /// A punctual light, by index into the scene's lights.
    Punctual(usize),
    /// The environment.
    Environment,
}

/// All emissive triangles and punctual lights of a scene and its environment, and the
/// distributions used to pick them.
pub struct LightSet {
    triangles: Vec<EmissiveTriangle>,
    punctual: Vec<LightKind>,
    environment: Option<EnvironmentLight>,
    /// What each entry of `distribution` is.
    lights: Vec<Light>,
    /// Over `lights`, by power: the scene's total, and whether anything emits.
    distribution: Distribution1d,
    /// Chooses among `lights` for each shading point.
    tree: LightTree,
    /// Index of the environment in `lights`, if it sends light.
    environment_index: Option<usize>,
    /// Over the delta lights alone (spheres weigh nothing), for estimators that find the
    /// others by hitting them.
    punctual_distribution: Distribution1d,
    /// Indices into `punctual` of the sphere lights, which bounce rays must look for.
    spheres: Vec<usize>,
    /// Radius of a sphere around the scene's geometry: directional lights and the
    /// environment are sampled from beyond it, and their power is what crosses its disc.
    scene_radius: f32,
    scene_center: Vec3,
    /// For each instance, the index of its mesh's first triangle in `triangles`, if emissive.
    first_of_instance: Vec<Option<u32>>,
    /// The motions of moving emissive instances.
    motions: Vec<Motion>,
}

impl LightSet {
    /// Collects the emissive triangles of every instance, the punctual lights and the
    /// environment.
    pub fn build(scene: &Scene) -> LightSet {
        let mut triangles = Vec::new();
        let mut first_of_instance = Vec::with_capacity(scene.instances.len());
        let mut motions = Vec::new();
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
            let motion = inst.motion.clone().map(|motion| {
                motions.push(motion);
                motions.len() as u32 - 1
            });
            for &[a, b, c] in &mesh.indices {
                let object = [a, b, c].map(|i| mesh.positions[i as usize]);
                triangles.push(EmissiveTriangle {
                    placed: PlacedTriangle::new(&m, object),
                    moving: motion.map(|k| (object, k)),
                    slice: inst.slice,
                    radiance: material.emission,
                    exitance: material.exitance(),
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
        let environment = scene
            .environment
            .as_ref()
            .filter(|e| !e.is_black())
            .map(EnvironmentLight::new);
        let mut lights: Vec<Light> = (0..triangles.len()).map(Light::Triangle).collect();
        lights.extend((0..punctual.len()).map(Light::Punctual));
        let environment_index = environment.as_ref().map(|_| {
            lights.push(Light::Environment);
            lights.len() - 1
        });
        let mut set = LightSet {
            triangles,
            punctual,
            environment,
            lights,
            distribution: Distribution1d::new(Vec::new()),
            tree: LightTree::default(),
            environment_index,
            punctual_distribution: Distribution1d::new(Vec::new()),
            spheres: Vec::new(),
            scene_radius,
            scene_center,
            first_of_instance,
            motions,
        };
        // A textured emitter counts with its texture's mean.
        let mut texture_means = HashMap::new();
        let mut texture_mean = |r: TextureRef| {
            *texture_means.entry(r.texture).or_insert_with(|| {
                let mean = scene.textures[r.texture].mean(ColorSpace::Srgb);
                mean.truncate().element_sum() / 3.0
            })
        };
        let weights: Vec<f32> = set
            .lights
            .iter()
            .map(|&light| set.power(light, &mut texture_mean))
            .collect();
        let bounds: Vec<TreeInput> = set
            .lights
            .iter()
            .zip(&weights)
            .map(|(&light, &power)| set.bounds(light, power))
            .collect();
        set.tree = LightTree::build(&bounds);
        set.distribution = Distribution1d::new(weights);
        set.punctual_distribution = Distribution1d::new(
            set.punctual
                .iter()
                .map(|l| match l {
                    LightKind::Sphere { .. } => 0.0,
                    _ => l.power(scene_radius),
                })
                .collect(),
        );
        set.spheres = (0..set.punctual.len())
            .filter(|&i| matches!(set.punctual[i], LightKind::Sphere { .. }))
            .collect();
        set
    }

    /// Where `light` can send light from and to and how strongly, for the light tree; for
    /// a light at infinity, the irradiance it brings (an environment's: its power, what
    /// crosses the scene's disc, over the disc). `power` is the light's [`LightSet::power`].
    /// A moving triangle is bounded over the whole shutter, with any normal.
    fn bounds(&self, light: Light, power: f32) -> TreeInput {
        let disc = std::f32::consts::PI * self.scene_radius * self.scene_radius;
        let at = |p: Vec3| Aabb { min: p, max: p };
        let intensity = match light {
            // A Lambertian emitter's intensity along its normal is radiance × area, and
            // its power π × radiance × area on each emitting side.
            Light::Triangle(i) => {
                let sides = if self.triangles[i].double_sided {
                    2.0
                } else {
                    1.0
                };
                power / (std::f32::consts::PI * sides)
            }
            Light::Punctual(i) => self.punctual[i].peak_intensity(),
            Light::Environment => 0.0,
        };
        let surface = |bounds, normals, two_sided| LightBounds {
            bounds,
            intensity,
            normals,
            cos_emission: 0.0,
            two_sided,
        };
        TreeInput::Placed(match light {
            Light::Triangle(i) => {
                let t = &self.triangles[i];
                let corners = |p: &PlacedTriangle| {
                    p.corners.iter().fold(Aabb::EMPTY, |b, c| b.union(at(c.0)))
                };
                match t.moving {
                    None => surface(
                        corners(&t.placed),
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
                                b.union(corners(&PlacedTriangle::new(key, object)))
                            }),
                        Cone::ALL,
                        true,
                    ),
                }
            }
            Light::Environment => {
                return TreeInput::Infinite(Distant {
                    irradiance: if disc > 0.0 { power / disc } else { power },
                    towards: None,
                });
            }
            Light::Punctual(i) => match self.punctual[i] {
                LightKind::Directional {
                    direction,
                    irradiance,
                } => {
                    return TreeInput::Infinite(Distant {
                        irradiance: irradiance.element_sum() / 3.0,
                        towards: Some(-direction),
                    });
                }
                LightKind::Point { position, .. } => surface(at(position), Cone::ALL, false),
                LightKind::Spot {
                    position,
                    direction,
                    cos_outer,
                    ..
                } => LightBounds {
                    // Nothing beyond the outer cone.
                    cos_emission: 1.0,
                    ..surface(
                        at(position),
                        Cone {
                            axis: direction,
                            cos_angle: cos_outer,
                        },
                        false,
                    )
                },
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
                        // Every point of the ball sends light only within the cone's
                        // directions (its falloff depends on the direction alone).
                        Some((axis, _, cos_outer)) => LightBounds {
                            cos_emission: 1.0,
                            ..surface(
                                ball,
                                Cone {
                                    axis,
                                    cos_angle: cos_outer,
                                },
                                false,
                            )
                        },
                        None => surface(ball, Cone::ALL, false),
                    }
                }
            },
        })
    }

    /// Emitted power of one light (W, mean over channels), for choosing among them; a
    /// textured triangle's scaled by its texture's mean, `texture_mean`.
    fn power(&self, light: Light, texture_mean: &mut impl FnMut(TextureRef) -> f32) -> f32 {
        match light {
            Light::Triangle(i) => {
                let t = &self.triangles[i];
                let scale = t.texture.map_or(1.0, |(r, _)| texture_mean(r));
                t.placed.area * t.exitance * scale
            }
            Light::Punctual(i) => self.punctual[i].power(self.scene_radius),
            Light::Environment => self
                .environment
                .as_ref()
                .map_or(0.0, |e| e.environment().power(self.scene_radius)),
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

    /// The environment, if it sends any light.
    pub fn environment_light(&self) -> Option<&EnvironmentLight> {
        self.environment.as_ref()
    }

    /// Draws a point on a light for shading point `p` with shading normal `n`: a light from
    /// the light tree, then a point on it by that light's own rule. `time` is the path's
    /// shutter time, for lights that move.
    pub fn sample(
        &self,
        scene: &Scene,
        p: Vec3,
        n: Vec3,
        time: f32,
        u_light: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (index, pmf) = self.tree.choose(p, n, u_light)?;
        match self.lights[index] {
            Light::Triangle(i) => self.sample_triangle(scene, i, pmf, p, time, u),
            Light::Punctual(i) => self.sample_punctual_light(i, pmf, p, u),
            Light::Environment => self.sample_environment(pmf, p, u),
        }
    }

    /// A point on triangle `index`: uniform over the solid angle it subtends at `p` where
    /// that is well conditioned ([`spherical`]), else uniform over its area, the density
    /// turned into solid angle by distance²/|cos θ_light|.
    fn sample_triangle(
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
        let directions = spherical::directions(p, corners);
        let omega = spherical::solid_angle_of(directions);
        let by_solid_angle = spherical::use_solid_angle(omega);
        let b = if by_solid_angle {
            spherical::sample_from(p, corners, directions, omega, u)?.1
        } else {
            uniform_triangle(u)
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
        let pdf = if by_solid_angle {
            pmf / omega as f32
        } else {
            pmf / placed.area * distance_sq / cos_light.abs()
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

    /// A direction towards the environment, as a point beyond the scene.
    fn sample_environment(&self, pmf: f32, p: Vec3, u: Vec2) -> Option<LightSample> {
        let (wi, radiance, pdf) = self.environment.as_ref()?.sample(u)?;
        let far = self.beyond_the_scene(p);
        Some(LightSample {
            point: p + far * wi,
            point_error: Vec3::ZERO,
            normal: -wi,
            wi,
            distance: far,
            radiance,
            pdf: pmf * pdf,
            is_delta: false,
        })
    }

    /// A distance from `p` that takes a segment past all of the scene.
    fn beyond_the_scene(&self, p: Vec3) -> f32 {
        2.0 * self.scene_radius + p.distance(self.scene_center) + 1.0
    }

    /// Radiance of the environment seen along `direction` by a ray that left the scene from
    /// `vertex` (shading normal `vertex_normal`), and the solid-angle density with which
    /// [`LightSet::sample`] there would have drawn it.
    pub fn environment(&self, vertex: Vec3, vertex_normal: Vec3, direction: Vec3) -> (Vec3, f32) {
        match (&self.environment, self.environment_index) {
            (Some(e), Some(index)) => {
                let direction = direction.normalize();
                (
                    e.radiance(direction),
                    self.tree.pmf(index, vertex, vertex_normal) * e.pdf(direction),
                )
            }
            _ => (Vec3::ZERO, 0.0),
        }
    }

    /// Draws a delta light alone, by power, for shading point `p`.
    pub fn sample_punctual(&self, p: Vec3, u_light: f32) -> Option<LightSample> {
        let (index, pmf) = self.punctual_distribution.sample(u_light)?;
        self.sample_punctual_light(index, pmf, p, Vec2::ZERO)
    }

    /// The contribution of scene light `index`, picked with probability `pmf`, at `p`.
    fn sample_punctual_light(
        &self,
        index: usize,
        pmf: f32,
        p: Vec3,
        u: Vec2,
    ) -> Option<LightSample> {
        let light = &self.punctual[index];
        let (point, radiance) = match *light {
            LightKind::Sphere {
                position,
                radius,
                radiance,
                ..
            } => {
                let s = sphere::sample(position, radius, p, u)?;
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
            } => {
                // From beyond the scene, so the shadow ray crosses all of it.
                (p - self.beyond_the_scene(p) * direction, irradiance)
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

    /// Calls `found` with the radiance, the light-sampling density (solid angle, seen from
    /// `vertex`) and the distance of every sphere light that a ray from `origin` along unit
    /// direction `d` passes before `t_max`. Spheres are not geometry: the ray goes on
    /// through them. `camera` asks for a camera ray, which sees only spheres visible to it.
    #[allow(clippy::too_many_arguments)]
    pub fn spheres_along(
        &self,
        vertex: Vec3,
        vertex_normal: Vec3,
        origin: Vec3,
        d: Vec3,
        t_max: f32,
        camera: bool,
        mut found: impl FnMut(Vec3, f32, f32),
    ) {
        for &i in &self.spheres {
            let light = &self.punctual[i];
            let LightKind::Sphere {
                position,
                radius,
                radiance,
                camera_visible,
                ..
            } = *light
            else {
                continue;
            };
            if camera && !camera_visible {
                continue;
            }
            if let Some(t) = sphere::intersect(position, radius, origin, d, 0.0, t_max) {
                let spot = light.spot_factor(-d);
                let pmf = self
                    .tree
                    .pmf(self.triangles.len() + i, vertex, vertex_normal);
                let pdf = pmf * sphere::pdf(position, radius, vertex);
                found(radiance * spot, pdf, t);
            }
        }
    }

    /// True when bounce rays must look for sphere lights.
    pub fn has_spheres(&self) -> bool {
        !self.spheres.is_empty()
    }

    /// The solid-angle density with which [`LightSet::sample`] at `origin` would pick the
    /// point of triangle `triangle` of instance `instance` at `distance` and light cosine
    /// `cos_light`.
    /// `time` is the shutter time of the ray that hit it.
    #[allow(clippy::too_many_arguments)]
    pub fn pdf(
        &self,
        instance: u32,
        triangle: u32,
        time: f32,
        origin: Vec3,
        origin_normal: Vec3,
        distance: f32,
        cos_light: f32,
    ) -> f32 {
        let Some(first) = self.first_of_instance[instance as usize] else {
            return 0.0;
        };
        let index = (first + triangle) as usize;
        let Some(placed) = self.placed_at(&self.triangles[index], time) else {
            return 0.0;
        };
        if placed.area == 0.0 || cos_light == 0.0 {
            return 0.0;
        }
        let pmf = self.tree.pmf(index, origin, origin_normal);
        if pmf == 0.0 {
            return 0.0;
        }
        let omega = spherical::solid_angle(origin, placed.corners.map(|c| c.0));
        if spherical::use_solid_angle(omega) {
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Light as SceneLight, SceneBuilder};

    #[test]
    fn a_spot_lamp_with_a_radius_is_never_chosen_outside_its_cone() {
        // A Blender spot lamp (a ball of radius 0.1 with a 30° cone, shining down) and a
        // point lamp: straight below the spot both count; beside it, outside the cone as
        // seen from every point of the ball, only the point lamp can be chosen.
        let mut builder = SceneBuilder::new();
        let down = -Vec3::Y;
        for kind in [
            LightKind::Sphere {
                position: Vec3::new(0.0, 2.0, 0.0),
                radius: 0.1,
                radiance: Vec3::splat(50.0),
                spot: Some((down, 25f32.to_radians().cos(), 30f32.to_radians().cos())),
                camera_visible: false,
            },
            LightKind::Point {
                position: Vec3::new(5.0, 2.0, 0.0),
                intensity: Vec3::ONE,
                range: None,
            },
        ] {
            builder.add_light(SceneLight {
                name: "lamp".into(),
                kind,
                source: "test".into(),
            });
        }
        let scene = builder.build();
        let set = LightSet::build(&scene);
        let spot = set
            .lights
            .iter()
            .position(|l| *l == Light::Punctual(0))
            .unwrap();
        let below = set.tree.pmf(spot, Vec3::ZERO, Vec3::Y);
        assert!(below > 0.5, "below the spot: {below}");
        assert_eq!(set.tree.pmf(spot, Vec3::new(3.0, 0.0, 0.0), Vec3::Y), 0.0);
    }
}
