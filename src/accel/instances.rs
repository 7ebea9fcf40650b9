//! The top level: one grid per mesh in object space, and a list of instances that place them.
//!
//! Rays are carried into each instance's object space, so a mesh used by many nodes is
//! stored once and never needs rebuilding (the "teapot in a stadium" stays cheap). Scenes
//! exported from Blender hold tens of objects, so the instances are tested in a flat list
//! after a bounding-box check.

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

use super::{Grid, Ray};
use crate::scene::{Aabb, Scene};

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
}

struct PlacedInstance {
    grid: usize,
    object_from_world: Affine3A,
    world_bounds: Aabb,
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
            .map(|inst| PlacedInstance {
                grid: inst.mesh,
                object_from_world: inst.world_from_object.inverse(),
                world_bounds: culling_bounds(
                    &scene.meshes[inst.mesh].bounds(),
                    &inst.world_from_object,
                ),
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
            if !hits_box(&inst.world_bounds, ray, t_max) {
                continue;
            }
            let local = to_object(ray, &inst.object_from_world).with_t_max(t_max);
            if let Some(hit) = self.grids[inst.grid].intersect(&local) {
                t_max = hit.t;
                best = Some(SceneHit {
                    t: hit.t,
                    instance: i as u32,
                    triangle: hit.triangle,
                    u: hit.u,
                    v: hit.v,
                });
            }
        }
        best
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.instances.iter().any(|inst| {
            hits_box(&inst.world_bounds, ray, ray.t_max)
                && self.grids[inst.grid].occluded(&to_object(ray, &inst.object_from_world))
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
