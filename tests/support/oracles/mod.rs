//! Independent ray-intersection oracles and the ray sets they are checked on, shared by the
//! cross-check test and the accelerator benchmark. Development only: Embree 4 (through
//! `embree4-sys`) and the `obvhs` CWBVH.
#![allow(dead_code)]

pub mod embree;
pub mod rays;

use std::path::{Path, PathBuf};
use std::time::Duration;

use glam::{Vec3, Vec3A};
use gridtrace::accel::{Ray, Triangle};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;

/// The dragon models `tools/dev/fetch-dragon.sh` unpacks, finest first.
pub const DRAGON_MODELS: [&str; 4] = [
    "dragon_vrip.ply.gz",
    "dragon_vrip_res2.ply.gz",
    "dragon_vrip_res3.ply.gz",
    "dragon_vrip_res4.ply.gz",
];

/// Path of a dragon model; panics with the fix when the data has not been fetched.
pub fn dragon_path(model: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/dragon")
        .join(model);
    assert!(
        path.is_file(),
        "{} is missing: run tools/dev/setup.sh (or tools/test.sh)",
        path.display()
    );
    path
}

/// A triangle soup: world-space positions and triangles.
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn triangles(&self) -> Vec<Triangle> {
        let p = &self.positions;
        self.indices
            .iter()
            .map(|&[a, b, c]| Triangle::new(p[a as usize], p[b as usize], p[c as usize]))
            .collect()
    }
}

/// The obvhs compressed-wide BVH (Ylitie et al. 2017) over a mesh.
pub struct Obvhs {
    pub bvh: CwBvh,
    triangles: Vec<obvhs::triangle::Triangle>,
}

fn to_a(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

impl Obvhs {
    pub fn build(mesh: &Mesh) -> Obvhs {
        let p = &mesh.positions;
        let triangles: Vec<obvhs::triangle::Triangle> = mesh
            .indices
            .iter()
            .map(|&[a, b, c]| obvhs::triangle::Triangle {
                v0: to_a(p[a as usize]),
                v1: to_a(p[b as usize]),
                v2: to_a(p[c as usize]),
            })
            .collect();
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &triangles,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        Obvhs { bvh, triangles }
    }

    fn ray(ray: &Ray) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(to_a(ray.origin), to_a(ray.direction), ray.t_min, ray.t_max)
    }

    /// Closest hit: (t, triangle index).
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, u32)> {
        let mut hit = obvhs::ray::RayHit::none();
        let tris = &self.triangles;
        let indices = &self.bvh.primitive_indices;
        if self.bvh.ray_traverse(Self::ray(ray), &mut hit, |r, id| {
            tris[indices[id] as usize].intersect(r)
        }) {
            Some((hit.t, indices[hit.primitive_id as usize]))
        } else {
            None
        }
    }

    /// obvhs's own test of triangle `id` alone: the hit distance, or infinity.
    pub fn triangle_hit(&self, id: u32, ray: &Ray) -> f32 {
        self.triangles[id as usize].intersect(&Self::ray(ray))
    }

    /// True when anything is hit within the ray's extent.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let tris = &self.triangles;
        let indices = &self.bvh.primitive_indices;
        !self.bvh.ray_traverse_miss(Self::ray(ray), |r, id| {
            tris[indices[id] as usize].intersect(r)
        })
    }

    /// Bytes of nodes, index list and triangles.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.bvh.nodes.as_slice())
            + std::mem::size_of_val(self.bvh.primitive_indices.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
    }
}
