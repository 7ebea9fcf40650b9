//! The shutter options: which interval a render's samples spread over (`--shutter`, or the
//! camera's own where the file says it) and at how many instants the scene is read.

use std::path::Path;

use anyhow::Result;

use super::args::{Args, parse_number};
use super::choose_camera;
use crate::load::motion::{MOTION_STEPS, over_shutter};
use crate::load::{LoadOptions, Loaded};

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

/// `loaded` with the motion of the shutter that `--shutter` or the chosen camera asks for
/// (none by default, as in Blender and USD), and the label that goes into the render
/// record ("" when still).
pub fn apply_shutter(
    loaded: Loaded,
    args: &Args,
    path: &Path,
    options: &LoadOptions,
) -> Result<(Loaded, String)> {
    let shutter = match args.shutter {
        Some(shutter) => Some(shutter),
        None => choose_camera(
            &loaded.scene,
            args.camera.as_deref(),
            args.width,
            args.height,
        )
        .ok()
        .and_then(|camera| camera.shutter),
    };
    let Some(shutter) = shutter.filter(|s| s[1] > s[0]) else {
        return Ok((loaded, String::new()));
    };
    let loaded = over_shutter(loaded, path, options, shutter, args.motion_steps)?;
    Ok((
        loaded,
        format!(
            " shutter={}..{} motion-steps={}",
            shutter[0], shutter[1], args.motion_steps
        ),
    ))
}
