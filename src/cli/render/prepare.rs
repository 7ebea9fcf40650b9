//! Preparing a render: the scene read (over the shutter, if one is open) and checked, its
//! environment set, the camera chosen once, and the render's settings.

use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};

use super::super::args::Args;
use super::super::camera::{CameraPick, camera_label, image_size, with_depth_of_field};
use super::super::choices::{GuidingChoice, Switch};
use super::super::environment::{
    EnvironmentSetting, EnvironmentSource, OBJECT_ON_NOTHING, apply_environment, studio_note,
};
use super::super::identity::IdentityInputs;
use super::super::inspect::describe;
use super::super::motion::{Shutter, apply_shutter};
use super::plan::{Plan, Request};
use crate::limits::check_memory;
use crate::load::access::folder_of;
use crate::load::load_scene_with;
use crate::record::{sha256_file, sha256_files};
use crate::render::{Film, Guiding, RenderSettings, Strategy, view_coverage};
use crate::scene::{Camera, Scene};

/// A scene ready to render, and how.
pub struct Prepared {
    /// The scene, environment set.
    pub scene: Scene,
    /// The camera, lens set.
    pub camera: Camera,
    /// What to render.
    pub settings: RenderSettings,
    /// The open shutter, if any.
    pub shutter: Option<Shutter>,
    /// The environment the render uses.
    pub environment: EnvironmentSetting,
    scene_sha256: String,
    dependencies_sha256: String,
}

impl Prepared {
    /// What the render identity needs beyond the camera and settings.
    pub fn identity_inputs<'a>(&'a self, args: &Args, plan: &'a Plan) -> IdentityInputs<'a> {
        IdentityInputs {
            scene_sha256: self.scene_sha256.clone(),
            dependencies_sha256: self.dependencies_sha256.clone(),
            load: &plan.request.load_options,
            shutter: self.shutter,
            environment: &self.environment,
            exposure: args.image.exposure,
        }
    }
}

/// The `--inspect` report: the scene as loaded, with its environment, and its warnings.
pub fn describe_for_inspection(args: &Args, request: &Request) -> Result<String> {
    let mut loaded = load_scene_with(request.scene_path, &request.load_options)?;
    apply_environment(&mut loaded.scene, &args.world, false)?;
    Ok(describe(&loaded.scene, &loaded.warnings))
}

/// Reads the scene as the plan says, checks it, and chooses the camera and settings.
pub fn prepare(args: &Args, plan: &Plan) -> Result<Prepared> {
    let Request {
        scene_path,
        load_options,
    } = &plan.request;
    let scene_sha256 =
        sha256_file(scene_path).with_context(|| format!("{}", scene_path.display()))?;
    let loaded = load_scene_with(scene_path, load_options)?;
    // The camera is chosen once, here; a wrong name is reported after the scene's warnings.
    let pick = CameraPick::choose(&loaded.scene, args.view.camera.as_deref());
    let camera_shutter = match &pick {
        Ok(pick) => pick
            .camera(&loaded.scene, args.view.width, args.view.height)
            .ok()
            .and_then(|camera| camera.shutter),
        Err(_) => None,
    };
    let (loaded, shutter) = apply_shutter(
        loaded,
        &args.motion,
        camera_shutter,
        scene_path,
        load_options,
    )?;
    let dependencies_sha256 = sha256_files(folder_of(scene_path), &loaded.files)
        .context("hashing the files the scene reads")?;
    for warning in &loaded.warnings {
        crate::terminal::say(format_args!("warning: {warning}"));
    }
    let mut scene = loaded.scene;
    for source in scene.drop_untraceable_instances() {
        crate::terminal::say(format_args!(
            "warning: {}: {source} reaches beyond {:e} from the origin, farther than 32-bit floats can trace; left out",
            scene_path.display(),
            crate::scene::MAX_COORDINATE
        ));
    }
    let camera = pick?.camera(&scene, args.view.width, args.view.height)?;
    let (camera, settings) = frame(args, plan, &scene, camera)?;
    // A scene lit only by its emissive surfaces gets the studio light too when the camera
    // sees mostly background: a product model whose only emitters are small details.
    // Not a scene of emitters alone (a neon sign in the dark): the lit object's own
    // surfaces must be seen more than its emitters.
    let coverage = (args.world.environment.is_none() && scene.lit_only_by_surfaces())
        .then(|| view_coverage(&scene, &camera, settings.width, settings.height));
    let object_on_nothing =
        coverage.is_some_and(|c| c.empty > OBJECT_ON_NOTHING && c.surfaces > c.emitters);
    let empty_share = coverage.filter(|_| object_on_nothing).map(|c| c.empty);
    let environment = apply_environment(&mut scene, &args.world, object_on_nothing)?;
    check_contents(args, plan, &scene, &environment, empty_share)?;
    Ok(Prepared {
        scene,
        camera,
        settings,
        shutter,
        environment,
        scene_sha256,
        dependencies_sha256,
    })
}

/// Refuses a scene over `--max-triangles`; says when the image will be empty or black, or
/// lit by the default studio light.
fn check_contents(
    args: &Args,
    plan: &Plan,
    scene: &Scene,
    environment: &EnvironmentSetting,
    empty_share: Option<f32>,
) -> Result<()> {
    let scene_path = plan.request.scene_path;
    let triangles = scene.instanced_triangle_count() as u64;
    if triangles > args.limits.max_triangles {
        bail!(
            "{}: {triangles} triangles after instancing, more than --max-triangles {}",
            scene_path.display(),
            args.limits.max_triangles
        );
    }
    if triangles == 0 {
        crate::terminal::say(format_args!(
            "warning: {}: the scene has no triangles; the image will be empty",
            scene_path.display()
        ));
    } else if environment.source == EnvironmentSource::Studio {
        crate::terminal::say(format_args!("{}", studio_note(scene_path, empty_share)));
    } else if !scene.has_emitters() {
        crate::terminal::say(format_args!(
            "warning: {}: the scene has no emitters (no emissive material, no light, no environment); the image will be black",
            scene_path.display()
        ));
    }
    Ok(())
}

/// The camera with its lens, checked, and the settings of an image of the size the
/// options and the camera's aspect ratio give, checked against the limits.
fn frame(
    args: &Args,
    plan: &Plan,
    scene: &Scene,
    camera: Camera,
) -> Result<(Camera, RenderSettings)> {
    let view = &args.view;
    let camera = with_depth_of_field(camera, view.fstop, view.focus_distance, scene);
    camera.validate().map_err(|why| {
        anyhow!(
            "{}: camera {}: {why}",
            plan.request.scene_path.display(),
            camera_label(&camera)
        )
    })?;
    let (width, height) = image_size(view.width, view.height, camera.aspect_ratio());
    let pixels = width as u64 * height as u64;
    if pixels > args.limits.max_pixels {
        bail!(
            "{width}x{height} is {pixels} pixels, more than --max-pixels {}",
            args.limits.max_pixels
        );
    }
    let sampling = &args.sampling;
    check_memory(
        || format!("a {width}x{height} film"),
        Film::bytes(width, height, plan.aovs, sampling.noise_threshold.is_some()),
    )?;
    if let (Some(w), Some(h), Some(aspect)) = (view.width, view.height, camera.aspect_ratio())
        && ((w as f32 / h as f32) / aspect - 1.0).abs() > 0.01
    {
        crate::terminal::say(format_args!(
            "note: {w}x{h} does not match the camera's aspect ratio {aspect:.3}; keeping its vertical field of view"
        ));
    }
    let filter = sampling.filter.into();
    let settings = RenderSettings {
        width,
        height,
        samples: plan.samples.clone(),
        max_depth: sampling.max_depth,
        seed: sampling.seed,
        strategy: Strategy::Mis,
        filter,
        filter_width: sampling
            .filter_width
            .unwrap_or_else(|| crate::render::FilterKind::default_width(filter)),
        aovs: plan.aovs,
        noise_threshold: sampling.noise_threshold,
        time_limit: sampling.time_limit.map(Duration::from_secs_f64),
        guiding: guiding_for(sampling.guiding),
        next_event_roulette: sampling.next_event_roulette == Switch::On,
        camera_grid: sampling.camera_grid == Switch::On,
    };
    Ok((camera, settings))
}

/// Whether to guide paths, as asked.
fn guiding_for(choice: GuidingChoice) -> Guiding {
    match choice {
        GuidingChoice::On => Guiding::On,
        GuidingChoice::Off => Guiding::Off,
    }
}
