//! The environment options: which environment lights the scene (the file's, one named on
//! the command line, or the default studio light when nothing else emits), how strong,
//! turned how far, and whether the camera sees it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::{Mat3, Vec3};

use super::args::EnvironmentArgs;
use super::values::EnvironmentChoice;
use crate::load::load_environment;
use crate::record::sha256_file;
use crate::scene::{Environment, Scene};

/// Where the environment that lights the render came from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    /// `--environment none`: black.
    None,
    /// `--environment R,G,B`.
    Constant(Vec3),
    /// `--environment FILE`, with the file's SHA-256.
    File {
        /// The file as named.
        path: PathBuf,
        /// Its SHA-256: a map replaced between parts stops their merge.
        sha256: String,
    },
    /// The default studio light, for a scene with no light at all.
    Studio,
    /// The scene's own (or none, if it has none).
    Scene,
}

/// The environment a render uses: where it came from and what the options did to it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentSetting {
    /// Where it came from.
    pub source: EnvironmentSource,
    /// `--environment-strength`.
    pub strength: f32,
    /// `--environment-rotation`, in degrees.
    pub rotation: f32,
    /// `--hide-environment`.
    pub hidden: bool,
}

/// The share of the view that must be empty background for a scene lit only by its own
/// emissive surfaces to get the default studio light too (see
/// [`crate::render::view_coverage`]): an object on nothing, not a lit interior.
pub const OBJECT_ON_NOTHING: f32 = 0.5;

/// Sets the scene's environment as the options say, and says what it became.
/// `object_on_nothing`: the scene is lit only by emissive surfaces and the camera sees
/// mostly background, so it gets the studio light as a scene without emitters does.
pub fn apply_environment(
    scene: &mut Scene,
    args: &EnvironmentArgs,
    object_on_nothing: bool,
) -> Result<EnvironmentSetting> {
    let source = match &args.environment {
        Some(EnvironmentChoice::None) => {
            scene.environment = None;
            EnvironmentSource::None
        }
        Some(EnvironmentChoice::Constant(c)) => {
            scene.environment = Some(Environment::constant(*c, "--environment"));
            EnvironmentSource::Constant(*c)
        }
        Some(EnvironmentChoice::File(path)) => {
            scene.environment = Some(load_environment(path)?);
            let sha256 = sha256_file(path).with_context(|| format!("{}", path.display()))?;
            EnvironmentSource::File {
                path: path.clone(),
                sha256,
            }
        }
        None if (!scene.has_emitters() || object_on_nothing)
            && scene.instanced_triangle_count() > 0 =>
        {
            scene.environment = Some(Environment::studio());
            EnvironmentSource::Studio
        }
        None => EnvironmentSource::Scene,
    };
    // Without an environment, escaping camera rays are black with alpha 0 already.
    if let Some(e) = &mut scene.environment {
        e.tint *= args.environment_strength;
        e.world_from_map =
            Mat3::from_rotation_y(args.environment_rotation.to_radians()) * e.world_from_map;
        if args.hide_environment {
            e.camera_visible = false;
        }
    }
    Ok(EnvironmentSetting {
        source,
        strength: args.environment_strength,
        rotation: args.environment_rotation,
        hidden: args.hide_environment,
    })
}

/// The note that says the default studio light was chosen, and how to choose another;
/// `empty_share` when the scene's emissive surfaces were its only light.
pub fn studio_note(scene_path: &Path, empty_share: Option<f32>) -> String {
    let why = match empty_share {
        None => "the scene has no lights".to_string(),
        Some(share) => format!(
            "only emissive surfaces light the scene and {:.0} % of the view is empty background",
            100.0 * share
        ),
    };
    format!(
        "note: {}: {why}; lighting it with the default studio environment \
         (--environment FILE.hdr or R,G,B for your own, --environment none for black)",
        scene_path.display()
    )
}
