//! gridtrace: a physically based CPU path tracer for scenes exported from Blender.
//!
//! Loaders ([`load`]) turn files into a [`scene::Scene`]; the renderer ([`render`]) traces
//! paths through per-mesh uniform grids ([`accel`]); [`output`] writes EXR or PNG, with a
//! [`record`] of what made the image, so that parts rendered apart can be [`merge`]d.
//!
//! ```
//! use glam::{Affine3A, Vec3};
//! use gridtrace::render::{RenderSettings, Renderer};
//! use gridtrace::scene::{Camera, Material, SceneBuilder};
//!
//! // A glowing quad seen head-on.
//! let mut b = SceneBuilder::new();
//! let glow = b.add_material(Material::diffuse("glow", Vec3::ZERO).with_emission(Vec3::splat(2.0)));
//! let quad = b.add_mesh(
//!     "quad",
//!     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)],
//!     vec![[0, 1, 2], [0, 2, 3]],
//!     glow,
//! );
//! b.add_instance(quad, Affine3A::IDENTITY, "quad");
//! let scene = b.build();
//! let camera = Camera::framing(&scene.bounds(), 1.0);
//! let renderer = Renderer::new(&scene);
//! let settings = RenderSettings { width: 8, height: 8, samples: 0..4, ..Default::default() };
//! let (image, _stats) = renderer.render(&camera, &settings, &|| {});
//! assert!((image.pixel(4, 4).x - 2.0).abs() < 1e-5);
//! ```
#![deny(missing_docs)]

pub mod accel;
pub mod cli;
pub mod geometry;
pub mod limits;
pub mod load;
pub mod output;
pub mod record;
pub mod render;
pub mod scene;
pub mod terminal;
