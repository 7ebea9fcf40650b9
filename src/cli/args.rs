//! The command line's arguments.

use std::ops::Range;
use std::path::PathBuf;

use clap::{Parser, Subcommand};

use super::choices::{
    FilterChoice, GuidingChoice, LightUnitsChoice, ProgressChoice, SoftFalloffChoice, Switch,
    ViewChoice,
};
use super::values::{
    EnvironmentChoice, parse_degrees, parse_distance, parse_environment, parse_exposure,
    parse_filter_width, parse_fps, parse_frame, parse_fstop, parse_motion_steps, parse_seconds,
    parse_shutter, parse_strength, parse_threshold,
};
use crate::limits::parse_size;
use crate::record::parse_range;
use crate::render::{AovSet, DEFAULT_MAX_DEPTH};

/// Render a glTF 2.0 (.gltf, .glb), USD (.usd, .usda, .usdc, .usdz) or PLY scene with a
/// physically based path tracer.
///
/// Materials are physically based (glTF's metallic-roughness model with its specular,
/// transmission, clear-coat and sheen extensions, which Blender's Principled BSDF, USD's
/// UsdPreviewSurface and MaterialX's OpenPBR and Standard Surface map onto); emissive
/// materials are area lights. Output is linear float
/// OpenEXR (.exr) or 8-bit sRGB PNG (.png), chosen by the output file's extension.
///
/// A long render can be split: `--samples A..B` renders only those samples of every pixel,
/// and `gridtrace merge` combines the parts into the image of one render.
#[derive(Parser, Debug)]
#[command(
    name = "gridtrace",
    version,
    about,
    long_about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    /// Something other than rendering.
    #[command(subcommand)]
    pub command: Option<Command>,

    /// Scene file to render (.gltf, .glb, .usd, .usda, .usdc, .usdz, .ply, .ply.gz).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,

    /// Print what was loaded (meshes, materials and how they were mapped, textures, lights
    /// with their power, cameras, warnings) and exit without rendering.
    #[arg(long)]
    pub inspect: bool,

    /// Worker threads. [default: one per core]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,

    /// What is written, and how it is shown on the way.
    #[command(flatten)]
    pub image: OutputArgs,

    /// How many samples each pixel takes, and how they are drawn.
    #[command(flatten)]
    pub sampling: SamplingArgs,

    /// Which camera renders, with what lens, at what image size.
    #[command(flatten)]
    pub view: CameraArgs,

    /// How the scene file is read: which frame, which files, which units.
    #[command(flatten)]
    pub loading: LoadArgs,

    /// Light from far away, and whether the camera sees it.
    #[command(flatten)]
    pub world: EnvironmentArgs,

    /// The shutter, and the instants at which a moving scene is read.
    #[command(flatten)]
    pub motion: MotionArgs,

    /// Sizes and times past which a scene is refused rather than rendered.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// What is written, and how it is shown on the way.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Output")]
pub struct OutputArgs {
    /// Output image, .exr (linear float RGBA) or .png (sRGB). [default: SCENE_STEM.exr in the current folder]
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Scale every output by 2^EV (EXR and PNG alike; recorded, so parts merge only at
    /// equal exposure).
    #[arg(long, value_name = "EV", default_value_t = 0.0, value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: f32,

    /// How a PNG shows the linear image: `standard` (the sRGB curve, clipping at 1) or
    /// `agx` (Blender's default view transform, which rolls highlights off). EXR stays linear.
    #[arg(long, value_enum, value_name = "VIEW", default_value = "standard")]
    pub view_transform: ViewChoice,

    /// Auxiliary layers written into the EXR beside the beauty, comma-separated: albedo,
    /// normal (of the first rough surface, through mirrors and glass, as denoisers want),
    /// depth (path length to it), position, variance (of the radiance samples), or all.
    #[arg(long, value_name = "LAYERS", value_parser = AovSet::parse)]
    pub aov: Option<AovSet>,

    /// Denoise the image with Intel Open Image Denoise, guided by the albedo and normal
    /// layers (kept in the EXR, with the noisy beauty as the `noisy` layer). Needs the OIDN
    /// 2 library; see docs/manual/outputs.md.
    #[arg(long)]
    pub denoise: bool,

    /// Every SECONDS, write the image so far to the output (atomically, as a part that
    /// `gridtrace merge` accepts), so a killed render keeps its samples.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub checkpoint: Option<f64>,

    /// Show the image as it converges in the tev viewer listening at HOST:PORT (tev's
    /// default is 127.0.0.1:14158). A viewer that goes away does not stop the render.
    #[arg(long, value_name = "HOST:PORT")]
    pub display: Option<String>,

    /// Report progress for a program to read: `json` prints a line after each pass but the
    /// last on stderr,
    /// `{"pass":K,"of":N,"seconds":T}` (K: samples per pixel taken so far; N: the most the
    /// render may take).
    #[arg(long, value_name = "FORMAT")]
    pub progress: Option<ProgressChoice>,

    /// No progress bar and no summary; warnings and errors are still printed.
    #[arg(short, long)]
    pub quiet: bool,
}

/// How many samples each pixel takes, and how they are drawn.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Sampling")]
pub struct SamplingArgs {
    /// Samples per pixel: more means less noise and a longer render. [default: 64; with
    /// --time-limit, as many as the time allows]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,

    /// Render only samples A to B−1 of every pixel, as one part of a render split across
    /// processes or machines; `gridtrace merge` combines the parts (write them as .exr).
    /// Any sample is the same whichever process renders it. [instead of --spp]
    #[arg(long, value_name = "A..B", value_parser = parse_range, conflicts_with = "spp")]
    pub samples: Option<Range<u32>>,

    /// Most bounces along a path; 0 shows emitters only, 1 direct light only.
    #[arg(long, default_value_t = DEFAULT_MAX_DEPTH)]
    pub max_depth: u32,

    /// Random seed: the same seed gives a bit-identical image, whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Adaptive sampling: a pixel stops once its estimated error (standard error over the
    /// square root of its intensity, as in Cycles) is below T, after at least max(16, √spp)
    /// samples. Such renders cannot be split with --samples. [typical: 0.01]
    #[arg(long, value_name = "T", value_parser = parse_threshold, conflicts_with = "samples")]
    pub noise_threshold: Option<f32>,

    /// Stop after this many seconds of rendering (no pass is started that would end
    /// later), writing the samples taken; the image's record says how many.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub time_limit: Option<f64>,

    /// Path guiding: a guide of the incident light, trained on the image's first 16 samples
    /// per pixel, proposes half the directions at diffuse surfaces. Off by default: it does
    /// not yet pay on the scenes measured (docs/benchmarks.md, "Path guiding").
    #[arg(long, value_enum, value_name = "WHEN", default_value = "off")]
    pub guiding: GuidingChoice,

    /// Next-event roulette: a pre-pass of a quarter sample per pixel finds the regions where
    /// light samples never reach their light (a room lit through glass, the ground under a
    /// glass ball); there they are taken one time in 16 and weighed by 16. Unbiased, and
    /// the same image on any thread count and across split renders.
    #[arg(long, value_enum, value_name = "WHEN", default_value = "on")]
    pub next_event_roulette: Switch,

    /// Camera rays through a grid of the camera's eye (a still pinhole camera, and at least
    /// eight camera rays per triangle in the scene): a speed-up that changes no pixel.
    #[arg(long, value_enum, value_name = "WHEN", default_value = "on")]
    pub camera_grid: Switch,

    /// Pixel filter, sampled by filter importance sampling (each sample lands in one pixel,
    /// weight 1, so parts still merge exactly). Cycles' default is blackman-harris 1.5.
    #[arg(long, value_enum, value_name = "FILTER", default_value = "box")]
    pub filter: FilterChoice,

    /// Width of the pixel filter in pixels. [default: 1 for box, 1.5 for the others]
    #[arg(long, value_name = "PIXELS", value_parser = parse_filter_width)]
    pub filter_width: Option<f32>,
}

/// Which camera renders, with what lens, at what image size.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Camera")]
pub struct CameraArgs {
    /// Camera to render, by name or by index in file order. [default: the first camera, or
    /// one that frames the whole scene if the file has none]
    #[arg(long, value_name = "NAME|INDEX")]
    pub camera: Option<String>,

    /// Image width in pixels. [default: from --height and the camera's aspect ratio]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub width: Option<u32>,

    /// Image height in pixels. [default: 512, or from --width and the camera's aspect ratio]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub height: Option<u32>,

    /// Depth of field: the lens's f-number (aperture diameter = focal length / N); 0 turns
    /// off the depth of field a USD camera has. The focal length is the camera's (USD) or,
    /// for cameras without one, that of a 24 mm-high sensor at its field of view, in metres.
    #[arg(long, value_name = "N", value_parser = parse_fstop)]
    pub fstop: Option<f32>,

    /// Distance to the plane in focus, in scene units. [default: the camera's, or the
    /// distance to the centre of the scene]
    #[arg(long, value_name = "DISTANCE", value_parser = parse_distance)]
    pub focus_distance: Option<f32>,
}

/// How the scene file is read: which frame, which files, which units.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Loading")]
pub struct LoadArgs {
    /// Frame at which to read an animated scene, as Blender numbers frames: a USD time code
    /// (transforms, points, cameras, lights); for glTF the time FRAME ÷ --fps seconds
    /// (node transforms, skins, morph weights). [default: USD's startTimeCode; glTF as
    /// stored, unanimated]
    #[arg(long, value_name = "FRAME", allow_negative_numbers = true, value_parser = parse_frame)]
    pub frame: Option<f64>,

    /// Frames per second turning --frame into glTF seconds (Blender's exporter writes
    /// keyframes at frame ÷ its scene's frame rate). [default: 24, Blender's]
    #[arg(long, value_name = "FPS", value_parser = parse_fps, requires = "frame")]
    pub fps: Option<f64>,

    /// The glTF animation --frame evaluates, by name or index. [default: the first]
    #[arg(long, value_name = "NAME|INDEX", requires = "frame")]
    pub animation: Option<String>,

    /// The glTF material variant (KHR_materials_variants) to render, by name or index.
    /// [default: each primitive's own material]
    #[arg(long, value_name = "NAME|INDEX")]
    pub material_variant: Option<String>,

    /// Levels of Catmull–Clark refinement for USD meshes whose subdivisionScheme asks for
    /// it (Blender exports a Subdivision modifier as its cage with catmullClark); 0 renders
    /// the cage. Each level has four times the faces. [default: 2, Blender's render level]
    #[arg(long, value_name = "LEVELS", value_parser = clap::value_parser!(u32).range(0..=6))]
    pub subdivision_level: Option<u32>,

    /// What glTF light intensities mean: the specification's candela and lux (Blender's
    /// "Standard" export), or Blender's "Unitless" or "Raw" lighting modes.
    #[arg(long, value_enum, value_name = "UNITS", default_value = "standard")]
    pub gltf_light_units: LightUnitsChoice,

    /// Blender's Soft Falloff for lamps with a radius in files Blender wrote (on by default
    /// in Blender and not written by its exporters): `auto` renders them as Cycles does,
    /// `off` as balls.
    #[arg(long, value_enum, value_name = "auto|off", default_value = "auto")]
    pub soft_falloff: SoftFalloffChoice,

    /// Another folder the scene may read files from (USD libraries shared between scenes),
    /// besides the scene file's own folder; repeatable. Nothing else is read.
    #[arg(long, value_name = "DIR")]
    pub asset_path: Vec<PathBuf>,
}

/// Light from far away, and whether the camera sees it.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Environment")]
pub struct EnvironmentArgs {
    /// Light from far away: a latitude–longitude (equirectangular) .hdr or .exr image,
    /// oriented as Blender's world shows it; a constant radiance, one number or R,G,B; or
    /// "none". Replaces the scene's own (a USD dome light). [default: the scene's; a neutral
    /// studio light when the scene has no light at all]
    #[arg(long, value_name = "FILE|R,G,B|none", allow_hyphen_values = true, value_parser = parse_environment)]
    pub environment: Option<EnvironmentChoice>,

    /// Multiplies the environment's radiance, whichever it is.
    #[arg(long, value_name = "FACTOR", default_value_t = 1.0, allow_negative_numbers = true, value_parser = parse_strength)]
    pub environment_strength: f32,

    /// Turns the environment about the up axis, in degrees (counter-clockwise seen from
    /// above).
    #[arg(long, value_name = "DEGREES", default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_degrees)]
    pub environment_rotation: f32,

    /// The environment lights the scene, but camera rays that miss everything see black with
    /// alpha 0 (a product shot over a transparent background).
    #[arg(long)]
    pub hide_environment: bool,
}

/// The shutter, and the instants at which a moving scene is read.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Motion blur")]
pub struct MotionArgs {
    /// Motion blur: the shutter's interval in frames relative to the frame rendered
    /// (`-0.25..0.25` is Blender's default half-frame shutter centred on the frame; `0..0`
    /// turns blur off). [default: the USD camera's shutter:open..shutter:close, else none]
    #[arg(long, value_name = "OPEN..CLOSE", value_parser = parse_shutter, allow_hyphen_values = true)]
    pub shutter: Option<[f64; 2]>,

    /// Instants across the shutter at which the scene is read (2 to 64): moving objects
    /// follow straight lines between them; deforming meshes are kept at each.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = parse_motion_steps)]
    pub motion_steps: usize,
}

/// Sizes and times past which a scene is refused rather than rendered.
#[derive(clap::Args, Debug, Clone)]
#[command(next_help_heading = "Limits")]
pub struct LimitArgs {
    /// Refuse scenes with more triangles than this (after instancing), before building
    /// anything; raise it to render bigger scenes.
    #[arg(long, value_name = "N", default_value_t = 200_000_000)]
    pub max_triangles: u64,

    /// Refuse images with more pixels than this; raise it to render bigger images.
    #[arg(long, value_name = "N", default_value_t = 1 << 28)]
    pub max_pixels: u64,

    /// Most memory to use (bytes, or with K, M, G, T: "16G"); larger films, parts and
    /// meshes are refused before they are allocated. [default: 80 % of the machine's
    /// memory, or the process's limit (ulimit -v) if lower]
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,

    /// Give up, with an error, if loading and preparing the scene take longer than this: a
    /// file on which a third-party reader loops must not hang a farm job.
    #[arg(long, value_name = "SECONDS", default_value_t = 600.0, value_parser = parse_seconds)]
    pub load_timeout: f64,
}

/// Commands other than rendering.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Combine EXR parts of one render (rendered with --samples) into one image, equal to
    /// the render of all their samples by one process.
    Merge(MergeArgs),
    /// Denoise an EXR gridtrace wrote (a merged render, say) with Intel Open Image Denoise,
    /// using its albedo and normal layers when it has them.
    Denoise(DenoiseArgs),
}

/// Arguments of `gridtrace denoise`.
#[derive(clap::Args, Debug)]
pub struct DenoiseArgs {
    /// The image to denoise: an EXR written by gridtrace (render or merge).
    #[arg(value_name = "IMAGE")]
    pub input: PathBuf,

    /// The denoised image, .exr (with the noisy beauty as its `noisy` layer) or .png.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,

    /// Worker threads. [default: one per core]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,

    /// No summary; errors are still printed.
    #[arg(short, long)]
    pub quiet: bool,

    /// Most memory to use; see `gridtrace --help`.
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,

    /// How a PNG output shows the linear image; see `gridtrace --help`.
    #[arg(long, value_enum, value_name = "VIEW", default_value = "standard")]
    pub view_transform: ViewChoice,
}

/// Arguments of `gridtrace merge`.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The parts: EXR files written by `gridtrace SCENE --samples A..B`, in any order.
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,

    /// The merged image, .exr (which can be merged again) or .png.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,

    /// Fail unless the parts hold exactly these samples, so a missing part is an error
    /// rather than a noisier image. [default: any contiguous range]
    #[arg(long, value_name = "A..B", value_parser = parse_range)]
    pub samples: Option<Range<u32>>,

    /// No summary; errors are still printed.
    #[arg(short, long)]
    pub quiet: bool,

    /// Most memory to use; see `gridtrace --help`.
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,

    /// Denoise the merged image (see `gridtrace --help`); parts rendered with --denoise
    /// merge by their noisy layers.
    #[arg(long)]
    pub denoise: bool,

    /// Worker threads for --denoise. [default: one per core]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,

    /// How a PNG output shows the linear image; see `gridtrace --help`.
    #[arg(long, value_enum, value_name = "VIEW", default_value = "standard")]
    pub view_transform: ViewChoice,
}
