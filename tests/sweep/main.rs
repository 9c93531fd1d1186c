//! `dustdem sweep`: cases skipped when finished, resumed from their checkpoint when killed, and
//! identical to a run of the case's own config by hand; bad sweep files named by field; and the
//! Slurm job array run for real on a single-node Slurm started on localhost, collected into the
//! same table a local sweep writes. Tiny CPU runs (200 monomers up to φ = 0.32) of the built
//! binary.

#[path = "../common/mod.rs"]
mod common;

mod refused_inputs;
mod resume_and_interrupt;
mod slurm_job_array;

use common::Scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dustdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
}

fn run(args: &[&str]) -> Output {
    dustdem().args(args).output().expect("dustdem runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// 200 RBD monomers pushed at 3 m/s up to φ = 0.32 (about 12 000 steps, 250 rows, a second of
/// CPU time), a checkpoint every 5 rows, no snapshots.
const BASE: &str = "[sample]\nmonomers = 200\nseed = 1\n[experiment]\nwall_speed_m_s = 3.0\n\
                    phi_stop = 0.32\naverage_steps = 50\n[output]\ncheckpoint_every_rows = 5\n\
                    snapshot_format = \"none\"\n";

/// Four cases: seeds 1 and 2, the paper's unmodified and modified models.
const SWEEP: &str = "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [3.0]\nseed = [1, 2]\n\
                     monomers = [200]\n[variants]\nunmodified = {}\n\
                     modified = { rolling_modifier = 8, sliding_modifier = 2.5 }\n";

const NAMES: [&str; 4] = [
    "v3.0_seed1_unmodified_n200",
    "v3.0_seed1_modified_n200",
    "v3.0_seed2_unmodified_n200",
    "v3.0_seed2_modified_n200",
];

/// Writes the base config and the sweep file into `dir`; returns the sweep file.
fn sweep_files(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let sweep = dir.join("sweep.toml");
    std::fs::write(&sweep, SWEEP).unwrap();
    sweep
}

/// `--precision` reaches each case's run: the case's log names the command it ran, and the
/// case finishes on the GPU engine in the mixed precision (where a device without f64 can be
/// made: lavapipe).
#[test]
fn each_case_runs_in_the_precision_the_sweep_was_given() {
    use dustdem::backend::gpu::context::{context_for_tests_with, ShaderF64};
    if context_for_tests_with(ShaderF64::Refused).is_none() {
        return;
    }
    let scratch = Scratch::new("sweep_precision");
    let sweep = sweep_files(scratch.path());
    let out = scratch.path().join("out");
    let result = run(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--backend",
        "gpu",
        "--precision",
        "mixed",
        "--case",
        "0",
    ]);
    assert!(result.status.success(), "{}", text(&result.stderr));
    let log = std::fs::read_to_string(out.join(NAMES[0]).join("sweep.log")).unwrap();
    assert!(log.contains(" --backend gpu --precision mixed "), "{log}");
    assert!(log.contains("filling factor reached phi_stop"), "{log}");
    let refused = run(&["sweep", sweep.to_str().unwrap(), "--precision", "half"]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(text(&refused.stderr).contains("expected exact, mixed or auto"));
}
