//! A programmatic way to assemble scenes, for tests, examples and loaders.

use glam::{Affine3A, Vec3};

use super::{Camera, Environment, Instance, Light, Material, Mesh, Scene, Texture};

/// Builds a [`Scene`] piece by piece.
///
/// ```
/// use gridtrace::scene::{Material, SceneBuilder};
/// use glam::{Affine3A, Vec3};
///
/// let mut b = SceneBuilder::new();
/// let white = b.add_material(Material::diffuse("white", Vec3::splat(0.8)));
/// let quad = b.add_mesh(
///     "floor",
///     vec![Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 1.0)],
///     vec![[0, 2, 1], [0, 3, 2]],
///     white,
/// );
/// b.add_instance(quad, Affine3A::IDENTITY, "floor");
/// let scene = b.build();
/// assert_eq!(scene.instanced_triangle_count(), 2);
/// ```
#[derive(Default)]
pub struct SceneBuilder {
    scene: Scene,
}

impl SceneBuilder {
    /// An empty scene.
    pub fn new() -> SceneBuilder {
        SceneBuilder::default()
    }

    /// Adds a material and returns its index.
    pub fn add_material(&mut self, material: Material) -> usize {
        self.scene.materials.push(material);
        self.scene.materials.len() - 1
    }

    /// Adds a mesh whose normals are computed from its triangles; returns its index.
    pub fn add_mesh(
        &mut self,
        name: impl Into<String>,
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        material: usize,
    ) -> usize {
        let normals = Mesh::compute_vertex_normals(&positions, &indices);
        self.add_full_mesh(Mesh {
            name: name.into(),
            positions,
            normals,
            uvs: Vec::new(),
            colours: Vec::new(),
            tangents: Vec::new(),
            indices,
            material,
        })
    }

    /// Adds a fully specified mesh; returns its index.
    pub fn add_full_mesh(&mut self, mesh: Mesh) -> usize {
        self.scene.meshes.push(mesh);
        self.scene.meshes.len() - 1
    }

    /// Places mesh `mesh` in the world.
    pub fn add_instance(
        &mut self,
        mesh: usize,
        world_from_object: Affine3A,
        source: impl Into<String>,
    ) {
        self.scene.instances.push(Instance {
            mesh,
            world_from_object,
            source: source.into(),
            motion: None,
            slice: None,
        });
    }

    /// Adds a camera.
    pub fn add_camera(&mut self, camera: Camera) {
        self.scene.cameras.push(camera);
    }

    /// The material at `index`, to adjust after loading.
    pub fn material_mut(&mut self, index: usize) -> &mut Material {
        &mut self.scene.materials[index]
    }

    /// A mesh added before.
    pub fn mesh(&self, index: usize) -> &Mesh {
        &self.scene.meshes[index]
    }

    /// A texture added before.
    pub fn texture(&self, index: usize) -> &Texture {
        &self.scene.textures[index]
    }

    /// Adds a decoded image; returns its index for [`super::TextureRef::texture`].
    pub fn add_texture(&mut self, texture: Texture) -> usize {
        self.scene.textures.push(texture);
        self.scene.textures.len() - 1
    }

    /// Adds constant radiance from every direction that misses the scene, summed with an
    /// earlier constant environment. Returns false, changing nothing, when the environment
    /// is already a map (the caller says what it drops).
    pub fn add_environment(&mut self, radiance: Vec3) -> bool {
        match &mut self.scene.environment {
            Some(e) if e.map.is_none() => e.tint += radiance,
            Some(_) => return false,
            None => self.scene.environment = Some(Environment::constant(radiance, "environment")),
        }
        true
    }

    /// True when an environment has been set or added.
    pub fn scene_environment_is_set(&self) -> bool {
        self.scene.environment.is_some()
    }

    /// Sets the environment, replacing any other.
    pub fn set_environment(&mut self, environment: Environment) {
        self.scene.environment = Some(environment);
    }

    /// Adds a punctual light.
    pub fn add_light(&mut self, light: Light) {
        self.scene.lights.push(light);
    }

    /// The finished scene.
    pub fn build(self) -> Scene {
        self.scene
    }
}
