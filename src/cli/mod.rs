//! The command-line driver: parse arguments, then render ([`render`]), merge parts rendered
//! apart ([`merge`]) or denoise an image ([`denoise`]). Errors exit with code 2; a render
//! stopped by a signal writes the image so far and exits with 128 + the signal's number
//! ([`signals`]).

mod args;
mod camera;
mod choices;
mod denoise;
mod environment;
mod identity;
mod inspect;
mod merge;
mod motion;
mod render;
pub(crate) mod signals;
mod values;

pub use args::{Args, Command, DenoiseArgs, MergeArgs};
pub use camera::{CameraPick, choose_camera, image_size, with_depth_of_field};

use std::sync::atomic::AtomicBool;

use anyhow::Result;
use clap::Parser;

/// How a run ended, when it did not fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// All samples were taken and the image written.
    Completed,
    /// A signal stopped the render early; the image written holds fewer samples.
    Interrupted,
}

/// Runs the command line and returns the process exit code: 0, 2 on errors, 128 + the
/// signal's number (130 for Ctrl-C, 143 for SIGTERM) when a signal stopped the render and
/// the partial image was written.
pub fn main() -> i32 {
    let args = Args::parse();
    signals::install();
    match run(&args, &signals::STOP) {
        Ok(Outcome::Completed) => 0,
        Ok(Outcome::Interrupted) => signals::interrupted_exit_code(),
        Err(e) => {
            crate::terminal::say(format_args!("error: {e:#}"));
            2
        }
    }
}

/// Runs what `args` says; a render stops early, and writes the image so far, once `stop`
/// is set.
pub fn run(args: &Args, stop: &AtomicBool) -> Result<Outcome> {
    match &args.command {
        Some(Command::Merge(merge)) => merge::run_merge(merge).map(|()| Outcome::Completed),
        Some(Command::Denoise(denoise)) => {
            denoise::run_denoise(denoise).map(|()| Outcome::Completed)
        }
        None => render::run_render(args, stop),
    }
}
