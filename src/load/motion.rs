//! Motion blur's scene: the file read again at instants across the shutter, folded into
//! one scene whose moving parts carry their motion.
//!
//! Reading the whole file at each instant lets every kind of animation the loaders know —
//! USD transforms, points, skinning and instancers; glTF node animation, skins and morph
//! targets — move without knowing about motion blur. Then, part by part:
//! - an instance whose transform changes gets the transforms at the instants
//!   ([`Motion`]: linear between neighbours; a moving instance is traced at each ray's
//!   time, nothing is rebuilt);
//! - a mesh whose points change (deformation) is kept at every instant, each copy seen
//!   during the part of the shutter nearest its instant ([`TimeSlice`]): a deforming mesh
//!   is rebuilt per time slice, so its blur is made of as many sharp copies as there are
//!   steps, and costs that many meshes' memory;
//! - a camera that moves gets its transforms too.
//!
//! Punctual lights, materials and the environment are read at the frame itself.

use std::path::Path;

use glam::Affine3A;

use super::{LoadError, LoadOptions, Loaded, load_scene_with};
use crate::scene::{Instance, Mesh, Motion, TimeSlice};

/// Fewest and most instants a shutter is read at.
pub const MOTION_STEPS: std::ops::RangeInclusive<usize> = 2..=64;

/// `loaded` (read at its frame) with the motion of the shutter `[open, close]` (frames
/// relative to that frame), read at `steps` evenly spaced instants. When the file has no
/// timeline, or its structure changes during the shutter (instances or triangles appear),
/// the scene is returned still, with a warning.
pub fn over_shutter(
    mut loaded: Loaded,
    path: &Path,
    options: &LoadOptions,
    shutter: [f64; 2],
    steps: usize,
) -> Result<Loaded, LoadError> {
    let Some(frame) = loaded.frame else {
        loaded.warnings.push(format!(
            "{}: the scene is not animated at a frame (glTF needs --frame), so there is no motion to blur",
            path.display()
        ));
        return Ok(loaded);
    };
    let steps = steps.clamp(*MOTION_STEPS.start(), *MOTION_STEPS.end());
    let mut instants = Vec::with_capacity(steps);
    for k in 0..steps {
        let time = frame + shutter[0] + (shutter[1] - shutter[0]) * k as f64 / (steps - 1) as f64;
        let at = LoadOptions {
            frame: Some(time),
            ..options.clone()
        };
        let mut scene = load_scene_with(path, &at)?.scene;
        // Only shapes and placements are kept from each instant.
        scene.textures = Vec::new();
        scene.environment = None;
        for mesh in &mut scene.meshes {
            mesh.uvs = Vec::new();
            mesh.colours = Vec::new();
        }
        if let Some(why) = structure_change(&loaded.scene, &scene) {
            loaded.warnings.push(format!(
                "{}: {why} at frame {time}; rendered without motion blur",
                path.display()
            ));
            return Ok(loaded);
        }
        instants.push(scene);
    }
    let scene = &mut loaded.scene;
    // Deforming meshes: the copy at each instant, the first in place of the mesh itself.
    let mut copies: Vec<Option<Vec<usize>>> = vec![None; scene.meshes.len()];
    for (m, copy) in copies.iter_mut().enumerate() {
        let deforms = instants
            .iter()
            .any(|s| s.meshes[m].positions != instants[0].meshes[m].positions);
        if !deforms {
            continue;
        }
        let mut indices = vec![m];
        let first = keyed_mesh(&scene.meshes[m], &instants[0].meshes[m]);
        for instant in &instants[1..] {
            scene.meshes.push(keyed_mesh(&first, &instant.meshes[m]));
            indices.push(scene.meshes.len() - 1);
        }
        scene.meshes[m] = first;
        *copy = Some(indices);
    }
    let mut instances = Vec::with_capacity(scene.instances.len());
    for (i, instance) in scene.instances.drain(..).enumerate() {
        let keys: Vec<Affine3A> = instants
            .iter()
            .map(|s| s.instances[i].world_from_object)
            .collect();
        let motion = Motion::from_keys(keys);
        match &copies[instance.mesh] {
            None => instances.push(Instance { motion, ..instance }),
            Some(indices) => {
                for (k, &mesh) in indices.iter().enumerate() {
                    instances.push(Instance {
                        mesh,
                        motion: motion.clone(),
                        slice: Some(TimeSlice::around_key(k, steps)),
                        ..instance.clone()
                    });
                }
            }
        }
    }
    scene.instances = instances;
    for (c, camera) in scene.cameras.iter_mut().enumerate() {
        camera.motion = Motion::from_keys(
            instants
                .iter()
                .map(|s| s.cameras[c].world_from_camera)
                .collect(),
        );
    }
    Ok(loaded)
}

/// Why `later` is not the same scene as `base` moved: something other than transforms and
/// points changed.
fn structure_change(base: &crate::scene::Scene, later: &crate::scene::Scene) -> Option<String> {
    if base.instances.len() != later.instances.len()
        || base.meshes.len() != later.meshes.len()
        || base.cameras.len() != later.cameras.len()
    {
        return Some("the number of objects changes".into());
    }
    if base
        .instances
        .iter()
        .zip(&later.instances)
        .any(|(a, b)| a.mesh != b.mesh)
    {
        return Some("objects change their meshes".into());
    }
    base.meshes
        .iter()
        .zip(&later.meshes)
        .find(|(a, b)| a.indices != b.indices || a.positions.len() != b.positions.len())
        .map(|(a, _)| format!("mesh '{}' changes its triangles", a.name))
}

/// `base` with the points (and what follows them) of its shape at another instant.
fn keyed_mesh(base: &Mesh, at: &Mesh) -> Mesh {
    Mesh {
        positions: at.positions.clone(),
        normals: at.normals.clone(),
        tangents: at.tangents.clone(),
        ..base.clone()
    }
}
