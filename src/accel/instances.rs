//! The top level: one grid per mesh in object space, and a list of instances that place them.
//!
//! Rays are carried into each instance's object space, so a mesh used by many nodes is
//! stored once and never needs rebuilding (the "teapot in a stadium" stays cheap). Scenes
//! exported from Blender hold tens of objects, so the instances are tested in a flat list
//! after a bounding-box check. A moving instance is placed at each ray's time, inside
//! bounds that hold it over the whole shutter; a time slice of a deforming mesh is seen
//! only by rays whose time falls in it.

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

use super::{Grid, Ray};
use crate::scene::{Aabb, Motion, Scene, TimeSlice};

/// A closest hit in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    /// Ray parameter (world-space ray).
    pub t: f32,
    /// Index into [`Scene::instances`].
    pub instance: u32,
    /// Triangle index within the instance's mesh.
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
    /// Shutter time of the ray that found it.
    pub time: f32,
}

struct PlacedInstance {
    grid: usize,
    object_from_world: Affine3A,
    world_bounds: Aabb,
    /// World-from-object over the shutter, when it moves.
    motion: Option<Motion>,
    slice: Option<TimeSlice>,
}

impl PlacedInstance {
    /// The ray in object space, or `None` when the instance is not there at its time or
    /// the ray misses its bounds.
    fn local_ray(&self, ray: &Ray, t_max: f32) -> Option<Ray> {
        if self.slice.as_ref().is_some_and(|s| !s.contains(ray.time))
            || !hits_box(&self.world_bounds, ray, t_max)
        {
            return None;
        }
        Some(match &self.motion {
            None => to_object(ray, &self.object_from_world),
            Some(motion) => to_object(ray, &motion.at(ray.time).inverse()),
        })
    }
}

/// Ray queries over a whole scene.
pub struct SceneAccel {
    grids: Vec<Grid>,
    instances: Vec<PlacedInstance>,
}

impl SceneAccel {
    /// Builds one grid per mesh (in parallel) and places the instances.
    pub fn build(scene: &Scene) -> SceneAccel {
        let grids: Vec<Grid> = scene
            .meshes
            .par_iter()
            .map(|mesh| Grid::from_mesh(mesh.positions.clone(), &mesh.indices))
            .collect();
        let instances = scene
            .instances
            .iter()
            .map(|inst| {
                let object = scene.meshes[inst.mesh].bounds();
                PlacedInstance {
                    grid: inst.mesh,
                    object_from_world: inst.world_from_object.inverse(),
                    world_bounds: match &inst.motion {
                        None => culling_bounds(&object, &inst.world_from_object),
                        Some(motion) => motion
                            .keys()
                            .iter()
                            .fold(Aabb::EMPTY, |b, key| b.union(culling_bounds(&object, key))),
                    },
                    motion: inst.motion.clone(),
                    slice: inst.slice,
                }
            })
            .collect();
        SceneAccel { grids, instances }
    }

    /// The grid built for mesh `mesh`.
    pub fn grid(&self, mesh: usize) -> &Grid {
        &self.grids[mesh]
    }

    /// The closest hit along `ray`.
    pub fn intersect(&self, ray: &Ray) -> Option<SceneHit> {
        let mut best: Option<SceneHit> = None;
        let mut t_max = ray.t_max;
        for (i, inst) in self.instances.iter().enumerate() {
            let Some(local) = inst.local_ray(ray, t_max) else {
                continue;
            };
            if let Some(hit) = self.grids[inst.grid].intersect(&local.with_t_max(t_max)) {
                t_max = hit.t;
                best = Some(SceneHit {
                    t: hit.t,
                    instance: i as u32,
                    triangle: hit.triangle,
                    u: hit.u,
                    v: hit.v,
                    time: ray.time,
                });
            }
        }
        best
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.instances.iter().any(|inst| {
            inst.local_ray(ray, ray.t_max)
                .is_some_and(|local| self.grids[inst.grid].occluded(&local))
        })
    }
}

/// World bounds for culling rays against an instance: the mesh's own bounds, transformed,
/// grown by a few ulps of their coordinates to cover rounding. Not the grid's bounds: those
/// are padded by a fraction of the mesh's size, and a ray leaving a flat mesh (a wall)
/// starts inside that padding, so it would walk the wall's grid for nothing.
fn culling_bounds(object: &Aabb, world_from_object: &Affine3A) -> Aabb {
    let b = object.transformed(world_from_object);
    if b.is_empty() {
        return b;
    }
    let pad = Vec3::splat(2.0 * f32::EPSILON * b.min.abs().max(b.max.abs()).max_element());
    Aabb {
        min: b.min - pad,
        max: b.max + pad,
    }
}

/// The ray in object space. The direction is transformed without normalising, so the
/// ray parameter `t` means the same point in both spaces.
fn to_object(ray: &Ray, object_from_world: &Affine3A) -> Ray {
    Ray {
        origin: object_from_world.transform_point3(ray.origin),
        direction: object_from_world.transform_vector3(ray.direction),
        ..*ray
    }
}

/// Slab test of the ray segment (`t_min`, `t_max`) against a box.
fn hits_box(b: &Aabb, ray: &Ray, t_max: f32) -> bool {
    let inv = ray.direction.recip();
    let t0 = (b.min - ray.origin) * inv;
    let t1 = (b.max - ray.origin) * inv;
    let near = t0.min(t1);
    // Widen each slab's exit by its rounding error, so a ray through the box is never
    // culled by rounding (pbrt-v4 §6.8.2: t_far·(1 + 2γ(3))).
    let far = t0.max(t1) * (1.0 + 2.0 * crate::accel::SLAB_ROUNDING);
    let t_start = ray.t_min.max(near.x).max(near.y).max(near.z);
    let t_end = t_max.min(far.x).min(far.y).min(far.z);
    t_start <= t_end
}
