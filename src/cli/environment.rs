//! The environment options: which environment lights the scene (the file's, one named on
//! the command line, or the default studio light when nothing else emits), how strong,
//! turned how far, and whether the camera sees it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::{Mat3, Vec3};

use super::args::{Args, parse_number};
use crate::load::load_environment;
use crate::record::sha256_file;
use crate::scene::{Environment, Scene};

/// What `--environment` asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentChoice {
    /// No environment at all: black.
    None,
    /// Constant radiance.
    Constant(Vec3),
    /// A latitude–longitude image file.
    File(PathBuf),
}

/// Parses `none`, one number, `R,G,B`, or anything else as a file name.
pub fn parse_environment(text: &str) -> Result<EnvironmentChoice, String> {
    if text.eq_ignore_ascii_case("none") {
        return Ok(EnvironmentChoice::None);
    }
    let numbers: Option<Vec<f32>> = text.split(',').map(|p| p.trim().parse().ok()).collect();
    match numbers.as_deref() {
        Some(&[v]) => colour(Vec3::splat(v), text),
        Some(&[r, g, b]) => colour(Vec3::new(r, g, b), text),
        Some(_) => Err(format!("'{text}' is neither one number, R,G,B nor a file")),
        None => Ok(EnvironmentChoice::File(PathBuf::from(text))),
    }
}

fn colour(c: Vec3, text: &str) -> Result<EnvironmentChoice, String> {
    if c.is_finite() && c.min_element() >= 0.0 {
        Ok(EnvironmentChoice::Constant(c))
    } else {
        Err(format!(
            "'{text}': radiance must be finite and not negative"
        ))
    }
}

/// A finite, non-negative strength.
pub fn parse_strength(text: &str) -> Result<f32, String> {
    let ok = |s: f32| s.is_finite() && s >= 0.0;
    parse_number(text, ok, "a finite, non-negative number")
}

/// A finite angle in degrees.
pub fn parse_degrees(text: &str) -> Result<f32, String> {
    parse_number(text, f32::is_finite, "a finite number of degrees")
}

/// Sets the scene's environment as the options say. Returns the note to print when the
/// default studio light was chosen, and the label the render record keeps.
pub fn apply_environment(
    scene: &mut Scene,
    args: &Args,
    scene_path: &Path,
) -> Result<(Option<String>, String)> {
    let mut note = None;
    let mut label = match &args.environment {
        Some(EnvironmentChoice::None) => {
            scene.environment = None;
            "none".to_string()
        }
        Some(EnvironmentChoice::Constant(c)) => {
            scene.environment = Some(Environment::constant(*c, "--environment"));
            format!("{},{},{}", c.x, c.y, c.z)
        }
        Some(EnvironmentChoice::File(path)) => {
            scene.environment = Some(load_environment(path)?);
            let sha = sha256_file(path).with_context(|| format!("{}", path.display()))?;
            format!("{} sha256={sha}", path.display())
        }
        None if !scene.has_emitters() && scene.instanced_triangle_count() > 0 => {
            scene.environment = Some(Environment::studio());
            note = Some(format!(
                "note: {}: the scene has no lights; lighting it with the default studio environment \
                 (--environment FILE.hdr or R,G,B for your own, --environment none for black)",
                scene_path.display()
            ));
            "studio".to_string()
        }
        None => "scene".to_string(),
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
    label = format!(
        "environment={label} strength={} rotation={}{}",
        args.environment_strength,
        args.environment_rotation,
        if args.hide_environment { " hidden" } else { "" }
    );
    Ok((note, label))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environment_option_reads_none_colours_and_files() {
        assert_eq!(parse_environment("none"), Ok(EnvironmentChoice::None));
        assert_eq!(
            parse_environment("0.5"),
            Ok(EnvironmentChoice::Constant(Vec3::splat(0.5)))
        );
        assert_eq!(
            parse_environment("0.1, 0.2,0.3"),
            Ok(EnvironmentChoice::Constant(Vec3::new(0.1, 0.2, 0.3)))
        );
        assert_eq!(
            parse_environment("sky.hdr"),
            Ok(EnvironmentChoice::File("sky.hdr".into()))
        );
        assert!(parse_environment("1,2").is_err());
        assert!(parse_environment("-1,0,0").is_err());
        assert!(parse_environment("nan").is_err());
    }
}
