//! Where each instance's grid lives and how it is built: a mesh used by several instances
//! (or moving) keeps one grid in object space; a mesh placed once and still gets a grid of
//! its own in world space ([`super::instances`] explains why). Also the world bounds the top
//! level culls rays by.

use glam::{Affine3A, Vec3};

use super::Grid;
use crate::geometry::Aabb;
use crate::scene::{Instance, Scene};

/// How the build places one scene instance.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Placement {
    /// Its mesh's grid in object space, shared with the mesh's other instances.
    Object,
    /// A grid of its own in world space.
    World,
}

/// What one grid is built over.
pub(super) enum GridSource {
    /// A mesh in object space, for all its instances placed there.
    Mesh(usize),
    /// One instance's mesh in world space.
    Instance(usize),
}

/// How each scene instance is placed: meshes used more than once, and moving instances,
/// stay in object space; a mesh placed once gets a world-space grid of its own.
pub(super) fn placements(scene: &Scene) -> Vec<Placement> {
    let mut uses = vec![0usize; scene.meshes.len()];
    for inst in &scene.instances {
        uses[inst.mesh] += 1;
    }
    scene
        .instances
        .iter()
        .map(|inst| {
            if uses[inst.mesh] > 1 || inst.motion.is_some() {
                Placement::Object
            } else {
                Placement::World
            }
        })
        .collect()
}

/// The grids to build, in a fixed order: object-space meshes, then world-space instances.
pub(super) fn grid_sources(scene: &Scene, placement: &[Placement]) -> Vec<GridSource> {
    let mut sources: Vec<GridSource> = (0..scene.meshes.len())
        .filter(|&mesh| {
            (scene.instances.iter().zip(placement))
                .any(|(inst, &p)| inst.mesh == mesh && p == Placement::Object)
        })
        .map(GridSource::Mesh)
        .collect();
    sources.extend(
        (0..scene.instances.len())
            .filter(|&i| placement[i] == Placement::World)
            .map(GridSource::Instance),
    );
    sources
}

/// Builds the grid of one source.
pub(super) fn build_grid(scene: &Scene, source: &GridSource) -> Grid {
    let world_positions = |inst: &Instance| -> Vec<Vec3> {
        let m = inst.world_from_object;
        let positions = &scene.meshes[inst.mesh].positions;
        positions.iter().map(|&p| m.transform_point3(p)).collect()
    };
    match source {
        GridSource::Mesh(mesh) => {
            let m = &scene.meshes[*mesh];
            Grid::from_mesh(m.positions.clone(), &m.indices)
        }
        GridSource::Instance(i) => {
            let inst = &scene.instances[*i];
            Grid::from_mesh(world_positions(inst), &scene.meshes[inst.mesh].indices)
        }
    }
}

/// World bounds of an instance over the whole shutter.
pub(super) fn instance_bounds(scene: &Scene, inst: &Instance) -> Aabb {
    let object = scene.meshes[inst.mesh].bounds();
    match &inst.motion {
        None => culling_bounds(&object, &inst.world_from_object),
        Some(motion) => motion
            .keys()
            .iter()
            .fold(Aabb::EMPTY, |b, key| b.union(culling_bounds(&object, key))),
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
