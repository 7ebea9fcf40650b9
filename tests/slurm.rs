//! The Slurm recipe end to end: starts a real single-node Slurm on this machine
//! (tools/user/slurm/local-cluster.sh), submits the bundled Cornell box as a job array of four
//! sample ranges and a dependent merge (tools/user/slurm/submit.sh), and checks the merged image
//! against one process rendering all the samples. The daemons it started are stopped by pid
//! whatever happens.
//!
//! Needs root and the Slurm and munge packages (tools/dev/install-slurm.sh, run by the test
//! command). Where neither can be had, `GRIDTRACE_SKIP_SLURM=1` skips it, saying so.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use gridtrace::output::merge::{MERGE_TOLERANCE, read_part};

const TASKS: u32 = 4;
const SPP: u32 = 256;
const WIDTH: &str = "128";

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A running local cluster; dropping it stops its daemons.
struct Cluster {
    dir: PathBuf,
}

impl Cluster {
    fn start(dir: PathBuf) -> Cluster {
        let cluster = Cluster { dir };
        let out = Command::new(repo().join("tools/user/slurm/local-cluster.sh"))
            .arg("start")
            .arg(&cluster.dir)
            .output()
            .expect("run tools/user/slurm/local-cluster.sh");
        assert!(
            out.status.success(),
            "starting Slurm failed (run tools/dev/install-slurm.sh as root, or set \
             GRIDTRACE_SKIP_SLURM=1 where Slurm cannot run):\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        cluster
    }

    fn conf(&self) -> PathBuf {
        self.dir.join("slurm.conf")
    }

    /// A command that talks to this cluster.
    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut command = Command::new(program);
        command.env("SLURM_CONF", self.conf());
        command
    }

    /// The state Slurm reports for a job (PENDING, RUNNING, COMPLETED, FAILED, …).
    fn job_state(&self, job: &str) -> String {
        let out = self
            .command("scontrol")
            .args(["show", "job", job])
            .output()
            .expect("run scontrol");
        let text = String::from_utf8_lossy(&out.stdout);
        text.split_whitespace()
            .find_map(|field| field.strip_prefix("JobState="))
            .unwrap_or("UNKNOWN")
            .to_string()
    }

    /// Waits until `job` leaves the queue and returns its final state.
    fn wait(&self, job: &str, limit: Duration) -> String {
        let start = Instant::now();
        loop {
            let state = self.job_state(job);
            if !matches!(
                state.as_str(),
                "PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING"
            ) {
                return state;
            }
            assert!(
                start.elapsed() < limit,
                "job {job} still {state} after {limit:?}"
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(repo().join("tools/user/slurm/local-cluster.sh"))
            .arg("stop")
            .arg(&self.dir)
            .status();
    }
}

#[test]
fn a_four_task_slurm_array_merges_to_the_single_process_render() {
    if std::env::var_os("GRIDTRACE_SKIP_SLURM").is_some_and(|v| v == "1") {
        eprintln!("GRIDTRACE_SKIP_SLURM=1: the Slurm test did not run");
        return;
    }
    let gridtrace = env!("CARGO_BIN_EXE_gridtrace");
    let scene = repo().join("assets/cornell_box.glb");
    let work = tempfile::tempdir().unwrap();
    let cluster = Cluster::start(work.path().join("cluster"));

    let single = work.path().join("single.exr");
    let start = Instant::now();
    let out = Command::new(gridtrace)
        .arg(&scene)
        .args(["--width", WIDTH, "--spp", &SPP.to_string(), "-q", "-o"])
        .arg(&single)
        .output()
        .unwrap();
    let single_time = start.elapsed();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let merged = work.path().join("slurm.exr");
    let start = Instant::now();
    let out = cluster
        .command(repo().join("tools/user/slurm/submit.sh"))
        .env("GRIDTRACE", gridtrace)
        .args(["--tasks", &TASKS.to_string(), "--spp", &SPP.to_string()])
        .arg(&scene)
        .arg(&merged)
        .args(["--width", WIDTH])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let ids = String::from_utf8_lossy(&out.stdout).into_owned();
    let (array, merge) = ids.trim().split_once(' ').expect("two job ids");
    let merge_state = cluster.wait(merge, Duration::from_secs(600));
    let slurm_time = start.elapsed();
    let logs = merged.with_extension("exr.parts");
    assert_eq!(
        merge_state,
        "COMPLETED",
        "merge job {merge} (after array {array}); logs in {}:\n{}",
        logs.display(),
        std::fs::read_to_string(logs.join("merge.log")).unwrap_or_default()
    );
    for task in 0..TASKS {
        let state = cluster.job_state(&format!("{array}_{task}"));
        assert_eq!(state, "COMPLETED", "array task {task}");
    }

    let single = read_part(&single).unwrap();
    let merged = read_part(&merged).unwrap();
    assert_eq!(merged.record.samples, 0..SPP);
    assert_eq!(merged.record.identity, single.record.identity);
    let (single, merged) = (single.read_image().unwrap(), merged.read_image().unwrap());
    assert_eq!(merged.alpha, single.alpha);
    let mut worst = 0.0f32;
    for (a, b) in merged.pixels.iter().zip(&single.pixels) {
        for c in 0..3 {
            let scale = a[c].max(b[c]);
            if scale > 0.0 {
                worst = worst.max((a[c] - b[c]).abs() / scale);
            }
        }
    }
    println!(
        "Slurm, {TASKS} tasks of 1 CPU: {:.2} s from submission to merged image; one process \
         on {} threads: {:.2} s; largest relative difference {worst:e}",
        slurm_time.as_secs_f64(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        single_time.as_secs_f64()
    );
    assert!(
        worst <= MERGE_TOLERANCE,
        "merged differs from one process by {worst:e} > {MERGE_TOLERANCE:e}"
    );
    drop(cluster);
}
