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

use glam::{Affine3A, Vec3, Vec4};

use super::{LoadError, LoadOptions, Loaded, load_scene_with};
use crate::limits::{bytes_of, check_memory};
use crate::scene::{Instance, Mesh, Motion, Scene, TimeSlice};

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
    let times: Vec<f64> = (0..steps)
        .map(|k| frame + shutter[0] + (shutter[1] - shutter[0]) * k as f64 / (steps - 1) as f64)
        .collect();
    // Each instant is read whole, then cut down to what moves; reading one takes about
    // what the scene at the frame took.
    let transient = scene_bytes(&loaded.scene);
    let mut instants: Vec<Instant> = Vec::with_capacity(steps);
    for (k, &time) in times.iter().enumerate() {
        check_memory(|| format!("motion step {} of {steps}", k + 1), transient).map_err(|e| {
            LoadError::Invalid {
                path: path.to_path_buf(),
                what: e.to_string(),
            }
        })?;
        // One crash probe, by the first read, covers every instant.
        let at = LoadOptions {
            frame: Some(time),
            probe_also_at: if k == 0 {
                times[1..].to_vec()
            } else {
                Vec::new()
            },
            probed: k > 0,
            ..options.clone()
        };
        let scene = load_scene_with(path, &at)?.scene;
        if let Some(why) = structure_change(&loaded.scene, &scene) {
            loaded.warnings.push(format!(
                "{}: {why} at frame {time}; rendered without motion blur",
                path.display()
            ));
            return Ok(loaded);
        }
        instants.push(Instant::of(scene, &loaded.scene));
    }
    let scene = &mut loaded.scene;
    // Deforming meshes: the copy at each instant, the first in place of the mesh itself.
    let mut copies: Vec<Option<Vec<usize>>> = vec![None; scene.meshes.len()];
    for (m, copy) in copies.iter_mut().enumerate() {
        let frame = &scene.meshes[m].positions;
        let first = instants[0].positions(m, frame);
        let deforms = instants.iter().any(|i| i.positions(m, frame) != first);
        if !deforms {
            continue;
        }
        let mut indices = vec![m];
        let first = keyed_mesh(&scene.meshes[m], instants[0].shapes[m].as_ref());
        for instant in &instants[1..] {
            scene
                .meshes
                .push(keyed_mesh(&first, instant.shapes[m].as_ref()));
            indices.push(scene.meshes.len() - 1);
        }
        scene.meshes[m] = first;
        *copy = Some(indices);
    }
    let mut instances = Vec::with_capacity(scene.instances.len());
    for (i, instance) in scene.instances.drain(..).enumerate() {
        let keys: Vec<Affine3A> = instants.iter().map(|s| s.instances[i]).collect();
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
        camera.motion = Motion::from_keys(instants.iter().map(|s| s.cameras[c]).collect());
    }
    Ok(loaded)
}

/// What motion blur keeps of the scene read at one instant: placements, and the shape of
/// each mesh whose points differ from the frame's.
struct Instant {
    instances: Vec<Affine3A>,
    cameras: Vec<Affine3A>,
    shapes: Vec<Option<Shape>>,
}

/// A mesh's points and what follows them.
struct Shape {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    tangents: Vec<Vec4>,
}

impl Instant {
    /// The points of mesh `m` at this instant (`frame`: its points at the frame).
    fn positions<'a>(&'a self, m: usize, frame: &'a [Vec3]) -> &'a [Vec3] {
        self.shapes[m].as_ref().map_or(frame, |s| &s.positions)
    }

    /// The parts of `scene` that move relative to `base` (same structure).
    fn of(scene: Scene, base: &Scene) -> Instant {
        Instant {
            instances: scene
                .instances
                .iter()
                .map(|i| i.world_from_object)
                .collect(),
            cameras: scene.cameras.iter().map(|c| c.world_from_camera).collect(),
            shapes: scene
                .meshes
                .into_iter()
                .zip(&base.meshes)
                .map(|(at, frame)| {
                    (at.positions != frame.positions).then_some(Shape {
                        positions: at.positions,
                        normals: at.normals,
                        tangents: at.tangents,
                    })
                })
                .collect(),
        }
    }
}

/// Bytes of a scene's meshes, the bulk of what reading it takes.
fn scene_bytes(scene: &Scene) -> u64 {
    scene
        .meshes
        .iter()
        .map(|m| {
            bytes_of::<Vec3>(m.positions.len() as u64 + m.normals.len() as u64)
                + bytes_of::<Vec4>(m.tangents.len() as u64)
                + bytes_of::<u32>(m.indices.len() as u64)
                + bytes_of::<glam::Vec2>(m.uvs.iter().map(|u| u.len() as u64).sum())
        })
        .sum()
}

/// Why `later` is not the same scene as `base` moved: something other than transforms and
/// points changed.
fn structure_change(base: &Scene, later: &Scene) -> Option<String> {
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

/// `base` with the points (and what follows them) of its shape at another instant, or as
/// it is when the shape there is the frame's.
fn keyed_mesh(base: &Mesh, at: Option<&Shape>) -> Mesh {
    match at {
        Some(shape) => Mesh {
            positions: shape.positions.clone(),
            normals: shape.normals.clone(),
            tangents: shape.tangents.clone(),
            ..base.clone()
        },
        None => base.clone(),
    }
}
