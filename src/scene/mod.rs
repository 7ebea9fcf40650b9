//! The internal scene: plain data that every loader produces and the renderer consumes.
//!
//! Nothing here knows about file formats or about acceleration structures. Each item keeps
//! a `source` string (glTF node index and name, USD prim path, …) so messages can say where
//! a problem came from.

mod builder;
mod camera;
mod environment;
mod light;
mod material;
mod mesh;
mod motion;
mod texture;

pub use builder::SceneBuilder;
pub use camera::{Camera, Projection, ThinLens};
pub use environment::{Environment, EnvironmentMap, blender_world_rotation, map_direction, map_uv};
pub use light::{Light, LightKind};
pub use material::{
    AlphaMode, Anisotropy, AnisotropyModel, ChannelRef, Material, MaterialTextures, Pbr,
    SheenModel, f0_of_ior,
};
pub use mesh::Mesh;
pub use motion::{Motion, TimeSlice};
pub use texture::{
    ColorSpace, Filter, Texture, TextureRef, UDIM_FIRST, UDIM_LAST, Wrap, linear_to_srgb,
    srgb_to_linear,
};

use glam::Affine3A;

use crate::geometry::Aabb;

/// One placement of a mesh in the world. Many instances may share one mesh.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Object-to-world transform.
    pub world_from_object: Affine3A,
    /// Where this instance came from, for messages.
    pub source: String,
    /// Its transform over the shutter, when it moves (`world_from_object` is then the
    /// transform at the frame itself, for everything that does not trace rays).
    pub motion: Option<Motion>,
    /// For one time slice of a deforming mesh: the part of the shutter it is seen in.
    pub slice: Option<TimeSlice>,
}

/// A complete scene ready to render.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Triangle meshes in object space.
    pub meshes: Vec<Mesh>,
    /// Placements of meshes in the world.
    pub instances: Vec<Instance>,
    /// Materials, indexed by [`Mesh::material`].
    pub materials: Vec<Material>,
    /// Cameras found in the file, in file order.
    pub cameras: Vec<Camera>,
    /// Punctual lights (point, spot, directional); emissive surfaces are not listed here.
    pub lights: Vec<Light>,
    /// Decoded images, indexed by [`TextureRef::texture`].
    pub textures: Vec<Texture>,
    /// Radiance arriving from every direction no geometry covers (a dome light, an HDR
    /// map); `None`: black.
    pub environment: Option<Environment>,
}

/// Farthest from the origin geometry may lie and still be traced: squared distances and
/// the products of ray–triangle tests overflow 32-bit floats (3.4·10³⁸) beyond about
/// 1.8·10¹⁹, and leave room for the scene's extent on top.
pub const MAX_COORDINATE: f32 = 1e18;

impl Scene {
    /// World-space bounds of every instance (over the whole shutter for moving ones).
    pub fn bounds(&self) -> Aabb {
        self.instances
            .iter()
            .fold(Aabb::EMPTY, |b, inst| b.union(self.instance_bounds(inst)))
    }

    /// World-space bounds of one instance.
    fn instance_bounds(&self, inst: &Instance) -> Aabb {
        let object = self.meshes[inst.mesh].bounds();
        match &inst.motion {
            None => object.transformed(&inst.world_from_object),
            Some(motion) => motion.bounds(&object),
        }
    }

    /// Leaves out the instances that reach beyond [`MAX_COORDINATE`] (or are not finite),
    /// which would otherwise come out as nothing without a word; returns their sources.
    pub fn drop_untraceable_instances(&mut self) -> Vec<String> {
        let traceable = |b: &Aabb| {
            b.is_empty()
                || (b.min.abs().max_element() <= MAX_COORDINATE
                    && b.max.abs().max_element() <= MAX_COORDINATE)
        };
        let keep: Vec<bool> = self
            .instances
            .iter()
            .map(|i| traceable(&self.instance_bounds(i)))
            .collect();
        let mut dropped = Vec::new();
        let mut flags = keep.iter();
        self.instances.retain(|i| {
            let kept = *flags.next().unwrap_or(&true);
            if !kept {
                dropped.push(i.source.clone());
            }
            kept
        });
        dropped
    }

    /// True when some instanced mesh has an emissive material or there is a punctual light.
    pub fn has_emitters(&self) -> bool {
        !self.lights.is_empty()
            || self.environment.as_ref().is_some_and(|e| !e.is_black())
            || self.instances.iter().any(|inst| {
                let mesh = &self.meshes[inst.mesh];
                self.materials[mesh.material].is_emissive() && !mesh.indices.is_empty()
            })
    }

    /// True when emissive surfaces are the only light: no lamps and no (or a black)
    /// environment.
    pub fn lit_only_by_surfaces(&self) -> bool {
        self.lights.is_empty()
            && self.environment.as_ref().is_none_or(|e| e.is_black())
            && self.has_emitters()
    }

    /// True when some geometry moves or deforms during the shutter.
    pub fn has_moving_geometry(&self) -> bool {
        self.instances
            .iter()
            .any(|i| i.motion.is_some() || i.slice.is_some())
    }

    /// Number of triangles after instancing.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh].indices.len())
            .sum()
    }
}
