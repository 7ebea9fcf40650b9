//! The lights next-event estimation samples — every triangle of an emissive material in
//! world space ([`triangle`]), every light of the scene's own ([`punctual`]: points, spots,
//! suns, sphere lamps), the environment ([`environment`]) — chosen for each shading point
//! by the light tree ([`tree`]) from their intensity and bounds. Each kind has its power,
//! bounds, sample and density in its own module; [`LightSet`] keeps the tree and the
//! distributions over them.

mod environment;
mod punctual;
mod quad;
mod sample;
mod sphere;
mod spherical;
mod spherical_rectangle;
mod tree;
mod triangle;

use glam::{Vec2, Vec3};

pub use environment::EnvironmentLight;
pub use sample::LightSample;
pub use triangle::EmissiveTriangles;

use super::sampling::Distribution1d;
use crate::scene::{LightKind, Scene};
use tree::{LightTree, TreeInput};
use triangle::Emitter;

/// One light of a [`LightSet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Light {
    /// An emissive triangle or rectangle.
    Emissive(Emitter),
    /// A light of the scene's own, by index into the scene's lights.
    Punctual(usize),
    /// The environment.
    Environment,
}

/// All emissive triangles and punctual lights of a scene and its environment, and the
/// distributions used to pick them.
pub struct LightSet {
    triangles: EmissiveTriangles,
    punctual: Vec<LightKind>,
    environment: Option<EnvironmentLight>,
    /// What each entry of `distribution` is: the triangles' emitters, then the punctual
    /// lights, then the environment.
    lights: Vec<Light>,
    /// For each emissive triangle, the index in `lights` of the emitter it belongs to.
    light_of_triangle: Vec<u32>,
    /// Over `lights`, by power: the scene's total, and whether anything emits.
    distribution: Distribution1d,
    /// Chooses among `lights` for each shading point.
    tree: LightTree,
    /// Index of the environment in `lights`, if it sends light.
    environment_index: Option<usize>,
    /// Over the delta lights alone (spheres weigh nothing), for estimators that find the
    /// others by hitting them.
    punctual_distribution: Distribution1d,
    /// Indices into `punctual` of the sphere lamps, which bounce rays must look for.
    spheres: Vec<usize>,
    /// Radius of a sphere around the scene's geometry: directional lights and the
    /// environment are sampled from beyond it, and their power is what crosses its disc.
    scene_radius: f32,
    scene_center: Vec3,
}

impl LightSet {
    /// Collects the emissive triangles of every instance, the punctual lights and the
    /// environment.
    pub fn build(scene: &Scene) -> LightSet {
        let triangles = EmissiveTriangles::collect(scene);
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
        let emitters = triangles.emitters();
        let light_of_triangle = triangles.emitter_indices(&emitters);
        let mut lights: Vec<Light> = emitters.iter().map(|&e| Light::Emissive(e)).collect();
        lights.extend((0..punctual.len()).map(Light::Punctual));
        let environment_index = environment.as_ref().map(|_| {
            lights.push(Light::Environment);
            lights.len() - 1
        });
        // Powers in the order of `lights`.
        let mut weights = triangles.powers(scene, &emitters);
        weights.extend(punctual.iter().map(|l| l.power(scene_radius)));
        weights.extend(
            environment
                .iter()
                .map(|e| e.environment().power(scene_radius)),
        );
        let disc = std::f32::consts::PI * scene_radius * scene_radius;
        let inputs: Vec<TreeInput> = lights
            .iter()
            .zip(&weights)
            .map(|(&light, &power)| match light {
                Light::Emissive(e) => triangles.tree_input(e, power),
                Light::Punctual(i) => punctual::tree_input(&punctual[i]),
                Light::Environment => EnvironmentLight::tree_input(power, disc),
            })
            .collect();
        let punctual_distribution = Distribution1d::new(
            punctual
                .iter()
                .map(|l| match l {
                    LightKind::Sphere { .. } => 0.0,
                    _ => l.power(scene_radius),
                })
                .collect(),
        );
        let spheres = (0..punctual.len())
            .filter(|&i| matches!(punctual[i], LightKind::Sphere { .. }))
            .collect();
        LightSet {
            tree: LightTree::build(&inputs),
            distribution: Distribution1d::new(weights),
            triangles,
            punctual,
            environment,
            lights,
            light_of_triangle,
            environment_index,
            punctual_distribution,
            spheres,
            scene_radius,
            scene_center,
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

    /// The emissive triangles.
    pub fn triangles(&self) -> &EmissiveTriangles {
        &self.triangles
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
            Light::Emissive(e) => self.triangles.sample(scene, e, pmf, p, time, u),
            Light::Punctual(i) => {
                punctual::sample(&self.punctual[i], pmf, p, self.beyond_the_scene(p), u)
            }
            Light::Environment => {
                let far = self.beyond_the_scene(p);
                self.environment.as_ref()?.sample_from(pmf, p, far, u)
            }
        }
    }

    /// The index in `lights` of the first punctual light.
    fn punctual_start(&self) -> usize {
        self.lights.len() - self.punctual.len() - usize::from(self.environment_index.is_some())
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
        let far = self.beyond_the_scene(p);
        punctual::sample(&self.punctual[index], pmf, p, far, Vec2::ZERO)
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
            if let Some((radiance, t)) =
                punctual::met_along(light, vertex, origin, d, t_max, camera)
            {
                let pmf = self
                    .tree
                    .pmf(self.punctual_start() + i, vertex, vertex_normal);
                found(radiance, pmf * punctual::sphere_pdf(light, vertex, d), t);
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
        let Some(index) = self.triangles.index_of(instance, triangle) else {
            return 0.0;
        };
        let light = self.light_of_triangle[index] as usize;
        let pmf = || self.tree.pmf(light, origin, origin_normal);
        self.triangles
            .pdf(index, pmf, time, origin, distance, cos_light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Light as SceneLight, Material, SceneBuilder};

    /// A square lamp of two triangles and a lone triangle beside it.
    fn lamps(square: [Vec3; 4]) -> Scene {
        let mut builder = SceneBuilder::new();
        let light = builder.add_material(Material {
            double_sided: false,
            ..Material::diffuse("light", Vec3::ZERO).with_emission(Vec3::splat(4.0))
        });
        let lone = [
            Vec3::new(3.0, 2.0, 0.0),
            Vec3::new(4.0, 2.0, 0.0),
            Vec3::new(3.0, 2.0, 1.0),
        ];
        let mut positions = square.to_vec();
        positions.extend(lone);
        let indices = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        let mesh = builder.add_mesh("lamps", positions, indices, light);
        builder.add_instance(mesh, glam::Affine3A::IDENTITY, "test");
        builder.build()
    }

    #[test]
    fn a_rectangle_of_two_triangles_is_one_light_that_rays_find_with_its_own_density() {
        // Facing down (wound clockwise seen from above), 1 × 0.6 at height 2.
        let square = [
            Vec3::new(-0.5, 2.0, -0.3),
            Vec3::new(-0.5, 2.0, 0.3),
            Vec3::new(0.5, 2.0, 0.3),
            Vec3::new(0.5, 2.0, -0.3),
        ];
        let scene = lamps(square);
        let set = LightSet::build(&scene);
        assert_eq!(
            set.lights,
            [
                Light::Emissive(Emitter::Quad(0)),
                Light::Emissive(Emitter::Triangle(2))
            ]
        );
        // From near (sampled by solid angle) and from far below (by area), each sample lands
        // on the lamp, and the density MIS would give a ray that found that point is the
        // one the sample was drawn with.
        let mut rng = crate::render::sampling::Rng::new(7, 3);
        let mut halves = [0; 2];
        for p in [Vec3::new(0.2, 1.4, 0.1), Vec3::new(0.0, -30.0, 0.0)] {
            for _ in 0..2000 {
                let u = rng.uniform2();
                let Some(s) = set.sample(&scene, p, Vec3::Y, 0.0, 0.1, u) else {
                    continue;
                };
                if s.point.x > 2.0 {
                    continue; // the lone triangle
                }
                assert!((s.point.y - 2.0).abs() < 1e-5 && s.point.x.abs() <= 0.5 + 1e-5);
                assert!(s.point.z.abs() <= 0.3 + 1e-5, "{}", s.point);
                // Which triangle the point is on: the diagonal from (-0.5, -0.3) to (0.5, 0.3).
                let triangle = u32::from(s.point.z < s.point.x * 0.6);
                halves[triangle as usize] += 1;
                let cos_light = s.normal.dot(-s.wi);
                let pdf = set.pdf(0, triangle, 0.0, p, Vec3::Y, s.distance, cos_light);
                assert!(
                    (pdf / s.pdf - 1.0).abs() < 1e-4,
                    "from {p} at {}: found with {pdf}, drawn with {}",
                    s.point,
                    s.pdf
                );
            }
        }
        assert!(halves.iter().all(|&h| h > 500), "{halves:?}");
    }

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
                soft: false,
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
