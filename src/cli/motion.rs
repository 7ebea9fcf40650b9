//! The shutter: which interval a render's samples spread over (`--shutter`, or the camera's
//! own where the file says it) and at how many instants the scene is read.

use std::path::Path;

use anyhow::Result;

use super::args::MotionArgs;
use crate::load::motion::over_shutter;
use crate::load::{LoadOptions, Loaded};

/// An open shutter: samples spread over `open..close` (frames relative to the frame
/// rendered), the scene read at `steps` instants across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shutter {
    /// When it opens, in frames.
    pub open: f64,
    /// When it closes, in frames.
    pub close: f64,
    /// Instants at which the scene is read.
    pub steps: usize,
}

/// `loaded` with the motion of the shutter that `--shutter`, else the chosen camera's
/// `camera_shutter`, asks for (none by default, as in Blender and USD), and that shutter
/// when it is open.
pub fn apply_shutter(
    loaded: Loaded,
    args: &MotionArgs,
    camera_shutter: Option<[f64; 2]>,
    path: &Path,
    options: &LoadOptions,
) -> Result<(Loaded, Option<Shutter>)> {
    let Some([open, close]) = args.shutter.or(camera_shutter).filter(|s| s[1] > s[0]) else {
        return Ok((loaded, None));
    };
    let loaded = over_shutter(loaded, path, options, [open, close], args.motion_steps)?;
    let shutter = Shutter {
        open,
        close,
        steps: args.motion_steps,
    };
    Ok((loaded, Some(shutter)))
}
