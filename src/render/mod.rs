//! Rendering: camera rays, BSDFs, lights, the path-tracing integrator and the film.
//!
//! [`Renderer`] holds everything derived from a [`Scene`] once (acceleration structure,
//! light list, BSDFs); [`Renderer::render`] turns a camera into an [`Image`].

mod bsdf;
mod camera;
mod film;
mod integrator;
mod lights;
pub mod sampling;
mod surface;

pub use bsdf::{Bsdf, BsdfSample, fresnel_dielectric};
pub use camera::RayGenerator;
pub use film::{Image, PixelAccumulator};
pub use integrator::{PathResult, Strategy};
pub use lights::{LightSample, LightSet};
pub use surface::{gamma, interpolate_with_error, offset_ray_origin, transform_point_with_error};

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::accel::SceneAccel;
use crate::scene::{Camera, Scene};
use sampling::{Rng, mix64};
use surface::InstanceFrame;

/// What to render and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Most scattering events along a path (0: emitters seen directly only).
    pub max_depth: u32,
    /// Seed of every random stream: the same seed gives the same image.
    pub seed: u64,
    /// Direct-light estimator.
    pub strategy: Strategy,
}

impl Default for RenderSettings {
    fn default() -> RenderSettings {
        RenderSettings {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 16,
            seed: 0,
            strategy: Strategy::Mis,
        }
    }
}

/// Counters of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Camera samples taken.
    pub samples: u64,
    /// Rays traced (camera, bounce and shadow).
    pub rays: u64,
    /// Samples that came out NaN or infinite and were dropped.
    pub nonfinite: u64,
    /// Wall-clock time of the pixel loop.
    pub elapsed: Duration,
}

/// A scene prepared for rendering.
pub struct Renderer<'a> {
    scene: &'a Scene,
    accel: SceneAccel,
    lights: LightSet,
    bsdfs: Vec<Bsdf>,
    frames: Vec<InstanceFrame>,
}

impl<'a> Renderer<'a> {
    /// Builds the acceleration structure and light list for `scene`.
    pub fn new(scene: &'a Scene) -> Renderer<'a> {
        Renderer {
            scene,
            accel: SceneAccel::build(scene),
            lights: LightSet::build(scene),
            bsdfs: scene.materials.iter().map(|m| Bsdf(m.kind)).collect(),
            frames: InstanceFrame::for_scene(scene),
        }
    }

    /// The scene's area lights.
    pub fn lights(&self) -> &LightSet {
        &self.lights
    }

    /// The acceleration structure.
    pub fn accel(&self) -> &SceneAccel {
        &self.accel
    }

    /// Renders an image. `on_row` is called once per finished row, from worker threads.
    ///
    /// Each pixel draws from its own random stream, seeded by the pixel index and the seed,
    /// and sums its samples in a fixed order, so the image is bit-identical for any number
    /// of threads.
    pub fn render(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        on_row: &(dyn Fn() + Sync),
    ) -> (Image, RenderStats) {
        let start = Instant::now();
        let generator = RayGenerator::new(camera, settings.width, settings.height);
        let width = settings.width as usize;
        let spp = settings.spp.max(1);
        let seed = mix64(settings.seed);
        let mut image = Image::new(settings.width, settings.height);
        let (rays, nonfinite) = image
            .pixels
            .par_chunks_mut(width)
            .zip(image.alpha.par_chunks_mut(width))
            .enumerate()
            .map(|(y, (radiance_row, alpha_row))| {
                let (mut rays, mut nonfinite) = (0u64, 0u64);
                for x in 0..width {
                    let mut rng = Rng::new(seed, (y * width + x) as u64);
                    let mut acc = PixelAccumulator::default();
                    for _ in 0..spp {
                        let jitter = rng.uniform2();
                        let ray = generator.generate(x as f32 + jitter.x, y as f32 + jitter.y);
                        let path =
                            self.trace_path(ray, &mut rng, settings.max_depth, settings.strategy);
                        rays += path.rays;
                        acc.add(path.radiance, path.hit);
                    }
                    nonfinite += acc.nonfinite as u64;
                    (radiance_row[x], alpha_row[x]) = acc.resolve(spp);
                }
                on_row();
                (rays, nonfinite)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        let mut stats = RenderStats {
            samples: spp as u64 * width as u64 * settings.height as u64,
            rays,
            nonfinite,
            elapsed: Default::default(),
        };
        stats.elapsed = start.elapsed();
        (image, stats)
    }
}
