//! The command line's values: each option's text checked and turned into what it means,
//! with a one-line error naming what was expected.

use std::path::PathBuf;

use glam::Vec3;

use crate::load::motion::MOTION_STEPS;

/// `text` as a number that `accepts`, or an error saying it is not `what`.
pub fn parse_number<T: std::str::FromStr + Copy>(
    text: &str,
    accepts: impl Fn(T) -> bool,
    what: &str,
) -> Result<T, String> {
    text.parse::<T>()
        .ok()
        .filter(|v| accepts(*v))
        .ok_or_else(|| format!("'{text}' is not {what}"))
}

/// A positive, finite frame rate.
pub fn parse_fps(text: &str) -> Result<f64, String> {
    parse_number(
        text,
        |x: f64| x.is_finite() && x > 0.0,
        "a positive frame rate",
    )
}

/// A finite frame number (USD time code).
pub fn parse_frame(text: &str) -> Result<f64, String> {
    parse_number(text, f64::is_finite, "a frame number")
}

/// A positive, finite number of seconds.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    parse_number(
        text,
        |s: f64| s.is_finite() && s > 0.0,
        "a positive number of seconds",
    )
}

/// A noise threshold: above 0, at most 1.
pub fn parse_threshold(text: &str) -> Result<f32, String> {
    parse_number(
        text,
        |t: f32| t.is_finite() && t > 0.0 && t <= 1.0,
        "a noise threshold above 0 and at most 1",
    )
}

/// A filter width: from 1/64 to 16 pixels.
pub fn parse_filter_width(text: &str) -> Result<f32, String> {
    let range = 1.0 / 64.0..=16.0;
    parse_number(
        text,
        |w| range.contains(&w),
        "a filter width from 1/64 to 16 pixels",
    )
}

/// An exposure adjustment in stops, within ±64.
pub fn parse_exposure(text: &str) -> Result<f32, String> {
    parse_number(
        text,
        |ev: f32| (-64.0..=64.0).contains(&ev),
        "an exposure from -64 to +64 stops",
    )
}

/// An f-number: finite and not negative (0: no depth of field).
pub fn parse_fstop(text: &str) -> Result<f32, String> {
    parse_number(
        text,
        |n: f32| n.is_finite() && n >= 0.0,
        "an f-number (0 or more)",
    )
}

/// A positive, finite distance.
pub fn parse_distance(text: &str) -> Result<f32, String> {
    parse_number(
        text,
        |d: f32| d.is_finite() && d > 0.0,
        "a positive distance",
    )
}

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

/// `OPEN..CLOSE` in frames relative to the frame rendered, `OPEN <= CLOSE`, both within
/// ±1000 frames (`0..0`: no motion blur, even where the file has a shutter).
pub fn parse_shutter(text: &str) -> Result<[f64; 2], String> {
    let (open, close) = text
        .split_once("..")
        .ok_or_else(|| format!("'{text}' is not OPEN..CLOSE"))?;
    let frames = |t: &str| {
        parse_number(
            t,
            |f: f64| (-1000.0..=1000.0).contains(&f),
            "a number of frames within ±1000",
        )
    };
    let shutter = [frames(open)?, frames(close)?];
    if shutter[1] < shutter[0] {
        return Err(format!("'{text}': the shutter closes before it opens"));
    }
    Ok(shutter)
}

/// A number of instants within [`MOTION_STEPS`].
pub fn parse_motion_steps(text: &str) -> Result<usize, String> {
    parse_number(
        text,
        |n| MOTION_STEPS.contains(&n),
        "a number of steps from 2 to 64",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_finite_numbers() {
        assert!(parse_frame("-3.5").is_ok() && parse_frame("inf").is_err());
    }

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
