//! Rendering: camera rays, BSDFs, lights, the path-tracing integrator and the film.
//!
//! [`Renderer`] holds everything derived from a [`Scene`] once (acceleration structure,
//! light list, BSDFs); [`Renderer::render`] turns a camera into an [`Image`].

pub(crate) mod adaptive;
pub(crate) mod aov;
mod batches;
mod bsdf;
mod camera;
#[cfg(test)]
mod chi_square;
mod coverage;
mod eye;
mod film;
mod filter;
mod guiding;
mod integrator;
mod lights;
mod next_event;
pub mod sampler;
pub mod sampling;
mod shading;
mod surface;

pub use aov::{AovImage, AovSet, Features};
pub use bsdf::{Bsdf, BsdfSample, fresnel_dielectric};
pub use camera::RayGenerator;
pub use coverage::{ViewCoverage, view_coverage};
pub use film::{Film, Image, PixelAccumulator};
pub use filter::{FilterKind, PixelFilter, profile as filter_profile};
pub use guiding::Guiding;
pub use integrator::{NextEvent, PathGuiding, PathOptions, PathResult, Strategy};
pub use lights::{EmissiveTriangles, LightSample, LightSet};
pub use next_event::{NextEventOdds, Outcome};

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::accel::{Ray, SceneAccel, TopLevel};
use crate::scene::{Camera, Scene};
use batches::{Batches, Bounds};
use guiding::{Guide, guiding_at};
use sampler::Sampler;
use sampling::mix64;
use surface::InstanceFrame;

/// Samples per pixel when nothing says how many.
pub const DEFAULT_SPP: u32 = 64;

/// Most bounces along a path when nothing says how many.
pub const DEFAULT_MAX_DEPTH: u32 = 16;

/// What to render and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Which samples of every pixel to take: `0..spp` for a whole render; a range
    /// `A..B` lets a long render be split among processes and merged (see
    /// [`crate::output::merge`]).
    pub samples: Range<u32>,
    /// Most scattering events along a path (0: emitters seen directly only).
    pub max_depth: u32,
    /// Seed of every random stream: the same seed gives the same image.
    pub seed: u64,
    /// Direct-light estimator.
    pub strategy: Strategy,
    /// Pixel reconstruction filter.
    pub filter: FilterKind,
    /// Its width in pixels.
    pub filter_width: f32,
    /// Auxiliary layers to keep.
    pub aovs: AovSet,
    /// Adaptive sampling: pixels stop once their estimated error falls below this
    /// ([`adaptive`]); `None` samples every pixel `spp` times.
    pub noise_threshold: Option<f32>,
    /// Stop starting passes once the next would end after this much time.
    pub time_limit: Option<Duration>,
    /// Path guiding: trained on the first samples when on ([`guiding`]).
    pub guiding: Guiding,
    /// Next-event roulette: light samples are taken rarely where a pre-pass found they
    /// never reach their light ([`next_event`]).
    pub next_event_roulette: bool,
    /// Camera rays asked first of a grid of the camera's eye when the image has enough of
    /// them to pay for its build ([`Renderer::eye_grid`]); the image is the same either way.
    pub camera_grid: bool,
}

impl Default for RenderSettings {
    fn default() -> RenderSettings {
        RenderSettings {
            width: 512,
            height: 512,
            samples: 0..DEFAULT_SPP,
            max_depth: DEFAULT_MAX_DEPTH,
            seed: 0,
            strategy: Strategy::Mis,
            filter: FilterKind::Box,
            filter_width: 1.0,
            aovs: AovSet::default(),
            noise_threshold: None,
            time_limit: None,
            guiding: Guiding::Off,
            next_event_roulette: true,
            camera_grid: true,
        }
    }
}

impl RenderSettings {
    /// Samples per pixel asked for.
    pub fn spp(&self) -> u32 {
        self.samples.len() as u32
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
    /// Samples per pixel taken: the requested count, or fewer if the render was stopped.
    pub spp: u32,
    /// Why the render ended before its last pass, if it did.
    pub ended_early: Option<EarlyEnd>,
}

/// Why a render took fewer passes than asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EarlyEnd {
    /// The stop flag was set (a signal).
    Stopped,
    /// Adaptive sampling: every pixel reached the noise threshold.
    Converged,
    /// One more sample per pixel would have ended after the time limit.
    TimeLimit,
}

/// Makes the image of the samples taken so far, for a checkpoint.
pub type ImageSoFar<'a> = &'a dyn Fn() -> (Image, RenderStats);

/// How a pixel's camera rays are made: the camera, the pixel filter, and whether a
/// shutter time is drawn.
pub(crate) struct CameraSampling {
    generator: RayGenerator,
    filter: PixelFilter,
    timed: bool,
}

impl CameraSampling {
    /// The camera ray of the sample `sampler` stands at, through pixel (`x`, `y`). It draws
    /// the filter offset, then a lens position only when there is a lens and a shutter
    /// time only when something moves, so that other images keep their random streams.
    pub(crate) fn ray(&self, x: usize, y: usize, sampler: &mut Sampler) -> Ray {
        let at = self.filter.sample(sampler.uniform2());
        let lens = if self.generator.has_lens() {
            sampler.uniform2()
        } else {
            glam::Vec2::splat(0.5)
        };
        let time = if self.timed { sampler.uniform() } else { 0.0 };
        let (px, py) = (x as f32 + at.x, y as f32 + at.y);
        self.generator.generate_through_lens(px, py, lens, time)
    }
}

/// A scene prepared for rendering.
pub struct Renderer<'a> {
    scene: &'a Scene,
    accel: SceneAccel,
    lights: LightSet,
    frames: Vec<InstanceFrame>,
    /// True when some material has alpha cutouts or blending, or is a lamp's shape, so
    /// hits must be checked.
    has_cutouts: bool,
    /// False when camera rays that leave the scene must see black (alpha 0).
    environment_visible: bool,
    /// Each material's BSDF for rays arriving on its front and on its back side, made once
    /// (materials that textures vary are made again at each hit).
    bsdfs: Vec<[Bsdf; 2]>,
}

impl<'a> Renderer<'a> {
    /// Builds the acceleration structure and light list for `scene`.
    pub fn new(scene: &'a Scene) -> Renderer<'a> {
        Renderer::with_top_level(scene, TopLevel::Automatic)
    }

    /// [`Renderer::new`] with the instances searched as asked (for benchmarks).
    pub fn with_top_level(scene: &'a Scene, top_level: TopLevel) -> Renderer<'a> {
        Renderer {
            scene,
            accel: SceneAccel::build_with(scene, top_level),
            lights: LightSet::build(scene),
            frames: InstanceFrame::for_scene(scene),
            has_cutouts: scene.materials.iter().any(|m| m.is_cutout() || m.lamp),
            environment_visible: scene.environment.as_ref().is_none_or(|e| e.camera_visible),
            bsdfs: scene
                .materials
                .iter()
                .map(|m| [Bsdf::new(&m.pbr, true), Bsdf::new(&m.pbr, false)])
                .collect(),
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

    /// Renders an image. `on_row` is called once per row per pass, from worker threads.
    pub fn render(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        on_row: &(dyn Fn() + Sync),
    ) -> (Image, RenderStats) {
        self.render_until(camera, settings, on_row, &AtomicBool::new(false))
    }

    /// Renders in passes over every pixel — one sample per pixel, then batches of samples
    /// that fill about a quarter of a second ([`batches`]) — stopping early after the pass
    /// during which `stop` becomes true; the image then holds the samples of the finished
    /// passes ([`Image::spp`]).
    ///
    /// Every sample draws from its own random stream, keyed by the seed, the pixel index and
    /// the sample index ([`Sampler::for_sample`]), and each pixel sums its samples in a fixed
    /// order, so the image is bit-identical for any number of threads, and a sample is the
    /// same whichever process renders it.
    pub fn render_until(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        on_row: &(dyn Fn() + Sync),
        stop: &AtomicBool,
    ) -> (Image, RenderStats) {
        self.render_with_checkpoints(camera, settings, on_row, stop, &mut |_, _| {})
    }

    /// [`Renderer::render_until`], calling `on_pass` after every pass but the last with the
    /// samples per pixel taken so far and a function that makes the image of them, for
    /// checkpoints: `on_pass` decides whether it is worth making.
    pub fn render_with_checkpoints(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        on_row: &(dyn Fn() + Sync),
        stop: &AtomicBool,
        on_pass: &mut dyn FnMut(u32, ImageSoFar),
    ) -> (Image, RenderStats) {
        let start = Instant::now();
        let view = CameraSampling {
            generator: RayGenerator::new(camera, settings.width, settings.height),
            filter: PixelFilter::new(settings.filter, settings.filter_width),
            timed: camera.motion.is_some() || self.scene.has_moving_geometry(),
        };
        let eye = settings
            .camera_grid
            .then(|| self.eye_grid(&view.generator, settings))
            .flatten();
        let first_sample = settings.samples.start;
        let spp = settings.spp().max(1);
        let seed = mix64(settings.seed);
        let adaptive = settings
            .noise_threshold
            .map(|t| adaptive::Schedule::new(t, spp));
        let odds = settings
            .next_event_roulette
            .then(|| self.learn_next_event_odds(&view, settings))
            .filter(|odds| odds.lowers_any());
        let next_event = odds.as_ref().map_or(NextEvent::Always, NextEvent::Roulette);
        let mut guide = (settings.guiding == Guiding::On).then(|| {
            let mut guide = Guide::new(self.scene.bounds());
            self.train_guide_before(&view, settings, &mut guide, first_sample, next_event);
            guide
        });
        let mut film = Film::new(
            settings.width,
            settings.height,
            first_sample,
            settings.aovs,
            adaptive.is_some(),
        );
        let mut stats = RenderStats::default();
        let image_so_far = |film: &Film, mut stats: RenderStats| {
            let (image, nonfinite) = film.resolve(stats.spp);
            stats.nonfinite = nonfinite;
            stats.elapsed = start.elapsed();
            (image, stats)
        };
        let mut batches = Batches::default();
        while stats.spp < spp {
            let batch_start = Instant::now();
            let sample = first_sample + stats.spp;
            let guiding = guiding_at(guide.as_ref(), sample);
            let passes = batches.next(Bounds {
                remaining: spp - stats.spp,
                until_check: adaptive.map(|a| a.passes_until_check(stats.spp)),
                training: matches!(guiding, PathGuiding::Train(_)),
                time_left: settings
                    .time_limit
                    .map(|limit| limit.saturating_sub(start.elapsed())),
            });
            let options = PathOptions {
                max_depth: settings.max_depth,
                strategy: settings.strategy,
                want_features: film.wants_features(),
                guiding,
                next_event,
                eye: eye.as_ref(),
            };
            let (rays, samples) = self.sweep(
                &mut film,
                &view,
                (seed, sample..sample + passes),
                options,
                on_row,
            );
            batches.record(passes, batch_start.elapsed());
            stats.rays += rays;
            stats.samples += samples;
            stats.spp += passes;
            if let Some(guide) = &mut guide {
                (sample..sample + passes).for_each(|s| guide.after_sample(s));
            }
            if stats.spp == spp {
                break;
            }
            if stop.load(Ordering::Relaxed) {
                stats.ended_early = Some(EarlyEnd::Stopped);
                break;
            }
            if let Some(schedule) = &adaptive
                && schedule.check_after(stats.spp)
                && film.update_active(|b, f, n| schedule.converged(b, f, n)) == 0
            {
                stats.ended_early = Some(EarlyEnd::Converged);
                break;
            }
            if let Some(limit) = settings.time_limit
                && start.elapsed() + batches.per_pass().unwrap_or_default() > limit
            {
                stats.ended_early = Some(EarlyEnd::TimeLimit);
                break;
            }
            on_pass(stats.spp, &|| image_so_far(&film, stats));
        }
        image_so_far(&film, stats)
    }

    /// Takes samples `samples` (with the seed before them) of every active pixel of `film`,
    /// in parallel over its rows; each pixel adds its samples in ascending order, so the
    /// sums do not depend on how the samples are batched. Returns the rays traced and the
    /// samples taken.
    fn sweep(
        &self,
        film: &mut Film,
        view: &CameraSampling,
        (seed, samples): (u64, Range<u32>),
        options: PathOptions,
        on_row: &(dyn Fn() + Sync),
    ) -> (u64, u64) {
        let width = film.width();
        film.rows()
            .into_par_iter()
            .map(|mut row| {
                let (mut rays, mut taken) = (0u64, 0u64);
                for x in 0..row.len() {
                    if !row.is_active(x) {
                        continue;
                    }
                    let pixel = (row.y * width + x) as u64;
                    for sample in samples.clone() {
                        let mut sampler = Sampler::for_sample(seed, pixel, sample);
                        let ray = view.ray(x, row.y, &mut sampler);
                        let path = self.trace_path_with(ray, &mut sampler, options);
                        rays += path.rays;
                        taken += 1;
                        row.add(x, path.radiance, path.hit, &path.features);
                    }
                }
                samples.clone().for_each(|_| on_row());
                (rays, taken)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::load_scene;

    /// Sweeps of several samples per pixel fill the film exactly as sweeps of one sample
    /// each: the same sums, bit for bit, features and all.
    #[test]
    fn batches_of_samples_fill_the_film_as_single_samples_do() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
        let scene = load_scene(&path).expect("the bundled scene loads").scene;
        let renderer = Renderer::new(&scene);
        let (width, height) = (24, 16);
        let view = CameraSampling {
            generator: RayGenerator::new(&scene.cameras[0], width, height),
            filter: PixelFilter::new(FilterKind::Box, 1.0),
            timed: false,
        };
        let options = PathOptions::plain(16, Strategy::Mis);
        let fill = |batches: &[u32]| {
            let mut film = Film::new(width, height, 0, AovSet::ALL, true);
            let options = PathOptions {
                want_features: true,
                ..options
            };
            let mut start = 0;
            for &n in batches {
                renderer.sweep(&mut film, &view, (7, start..start + n), options, &|| {});
                start += n;
            }
            film.resolve(start).0
        };
        let one_by_one = fill(&[1; 11]);
        let batched = fill(&[1, 2, 8]);
        assert_eq!(one_by_one.pixels, batched.pixels);
        assert_eq!(one_by_one.alpha, batched.alpha);
        assert_eq!(one_by_one.aovs, batched.aovs);
        assert!(one_by_one.pixels.iter().any(|p| p.max_element() > 0.0));
    }
}
