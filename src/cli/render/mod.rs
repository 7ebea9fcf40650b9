//! Rendering a scene, in four steps: plan what to do from the options ([`plan`]), prepare
//! the scene, camera and settings ([`prepare`]), render in passes with checkpoints and the
//! live view ([`passes`]), then report and write ([`report`]).

mod passes;
mod plan;
mod prepare;
mod report;

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Context, Result};

use super::Outcome;
use super::args::Args;
use super::identity::render_identity;
use super::signals::{Phase, set_phase};
use crate::render::Renderer;

/// Loads, renders and writes as `args` says; rendering stops early, and the image so far is
/// written, once `stop` is set.
pub fn run_render(args: &Args, stop: &AtomicBool) -> Result<Outcome> {
    let request = plan::read_request(args)?;
    if args.inspect {
        let report = prepare::describe_for_inspection(args, &request)?;
        set_phase(Phase::Finished);
        crate::terminal::print_report(&format!("{}:\n{report}", request.scene_path.display()));
        return Ok(Outcome::Completed);
    }
    let plan = plan::plan_outputs(args, request)?;
    let load_start = Instant::now();
    let prepared = prepare::prepare(args, &plan)?;
    // The workers start only now: a USD stage is first read in a forked child, and a
    // worker caught starting up at the fork (initialising a process-wide value its thread
    // pool shares with the child's image decoders) would leave the child waiting for ever.
    let pool = thread_pool(args.threads)?;
    let renderer = pool.install(|| Renderer::new(&prepared.scene));
    if !args.image.quiet {
        report::prepared(&plan, &prepared, &renderer, load_start.elapsed());
    }
    let identity = render_identity(
        prepared.identity_inputs(args, &plan),
        &prepared.camera,
        &prepared.settings,
    );
    let rendered = passes::render_passes(args, &plan, &prepared, &renderer, &pool, identity, stop);
    report::finish(args, &plan, &prepared, rendered)
}

/// The worker threads: `--threads`, else one per core.
fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n as usize);
    }
    pool.build().context("starting worker threads")
}
