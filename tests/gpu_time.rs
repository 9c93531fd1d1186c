//! One definition of simulated time: `time_s` is step × dt, bit for bit, in curve.csv and
//! profiles.csv, and a short run on each backend writes the same column, although the CPU
//! engine counts its steps one by one and the GPU engine in submissions of many.

mod common;
mod gpu_support;

use common::Scratch;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::config::Config;
use dustdem::output::csv::read_csv;
use std::path::Path;
use std::process::Command;

/// 20 rows of 100 steps, a profile every 4 rows; the GPU submits 100 steps at a time.
const CONFIG: &str = "[sample]\nmonomers = 200\nseed = 4\n[experiment]\nmax_steps = 2000\n\
                      average_steps = 100\nprofile_every_rows = 4\n[output]\n\
                      snapshot_format = \"none\"\n";

/// (step, time_s) of each row.
type Times = Vec<(f64, f64)>;

/// The (step, time_s) pairs of `file` in `out`.
fn times(out: &Path, file: &str) -> Times {
    let (header, rows) = read_csv(out.join(file)).unwrap();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (step, time) = (column("step"), column("time_s"));
    rows.iter().map(|r| (r[step], r[time])).collect()
}

/// Runs the config in `dir` on `backend`: the times of curve.csv and of profiles.csv.
fn run(dir: &Path, backend: &str) -> (Times, Times) {
    let out = dir.join(backend);
    let result = Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args([
            "run",
            dir.join("run.toml").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--backend",
            backend,
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{backend}: {}",
        String::from_utf8_lossy(&result.stderr)
    );
    (times(&out, "curve.csv"), times(&out, "profiles.csv"))
}

#[test]
fn both_backends_write_the_same_time_column() {
    let dir = Scratch::new("gpu-time");
    std::fs::write(dir.join("run.toml"), CONFIG).unwrap();
    let dt = Config::parse(CONFIG, "time test").unwrap().dt();
    let (curve, profiles) = run(&dir, "cpu");
    assert_eq!(curve.len(), 21, "the start and 20 rows");
    for (step, time) in curve.iter().chain(&profiles) {
        let want = *step as u64 as f64 * dt;
        assert_eq!(
            time.to_bits(),
            want.to_bits(),
            "step {step}: {time:e} != {want:e}"
        );
    }
    if context_for_tests().is_none() {
        return;
    }
    let (gpu_curve, gpu_profiles) = run(&dir, "gpu");
    let bits = |v: &[(f64, f64)]| -> Vec<(u64, u64)> {
        v.iter().map(|(s, t)| (s.to_bits(), t.to_bits())).collect()
    };
    assert_eq!(bits(&curve), bits(&gpu_curve), "curve.csv step and time_s");
    assert_eq!(
        bits(&profiles),
        bits(&gpu_profiles),
        "profiles.csv step and time_s"
    );
}
