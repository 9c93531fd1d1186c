//! The Slurm job array, run on a single-node Slurm started on localhost, collects into the same
//! table a local sweep writes.

use super::*;
use crate::common::slurm::{slurm_available, LocalSlurm};
use std::time::{Duration, Instant};

/// sweep.csv without its wall-clock column.
fn without_wall_clock(table: &str) -> Vec<Vec<String>> {
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == "wall_clock_s").unwrap();
    std::iter::once(header.join(","))
        .chain(lines.map(str::to_string))
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|(_, f)| f.to_string())
                .collect()
        })
        .collect()
}

#[test]
fn a_slurm_job_array_runs_the_sweep_as_a_local_sweep_does() {
    if !slurm_available() {
        return;
    }
    let dir = Scratch::new("sweep-slurm");
    let sweep = sweep_files(&dir);
    let (on_slurm, local) = (dir.join("on_slurm"), dir.join("local"));
    let export = run(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        on_slurm.to_str().unwrap(),
        "--backend",
        "cpu",
        "--slurm",
        "--time",
        "00:05:00",
        "--mem-mb",
        "500",
    ]);
    assert!(export.status.success(), "{}", text(&export.stderr));
    let script_path = on_slurm.join("sweep.sbatch");
    let script = std::fs::read_to_string(&script_path).unwrap();
    for line in [
        "#SBATCH --array=0-3\n",
        "#SBATCH --cpus-per-task=1\n",
        "#SBATCH --time=00:05:00\n",
        "#SBATCH --mem=500M\n",
    ] {
        assert!(script.contains(line), "{line} in:\n{script}");
    }
    assert!(script.contains(env!("CARGO_BIN_EXE_dustdem")), "{script}");
    let cases = std::fs::read_to_string(on_slurm.join("cases.csv")).unwrap();
    assert_eq!(
        cases
            .lines()
            .filter(|l| l.starts_with(char::is_numeric))
            .count(),
        4
    );

    let slurm_dir = dir.join("slurm");
    let started = Instant::now();
    let mut slurm = LocalSlurm::start(&slurm_dir);
    let ready = started.elapsed();
    let job = slurm.submit(&script_path, &dir);
    slurm.wait(&job, Duration::from_secs(180));
    let finished = started.elapsed();
    drop(slurm);
    eprintln!(
        "slurm: daemons up in {:.1} s, array done {:.1} s after start, stopped after {:.1} s",
        ready.as_secs_f64(),
        finished.as_secs_f64(),
        started.elapsed().as_secs_f64()
    );
    let task_logs = std::fs::read_dir(on_slurm.join("slurm")).unwrap().count();
    assert_eq!(task_logs, 4, "one output file per array task");

    let collected = run(&["sweep", "collect", on_slurm.to_str().unwrap()]);
    assert!(
        collected.status.success(),
        "{}{}",
        text(&collected.stdout),
        text(&collected.stderr)
    );

    let local_run = run(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        local.to_str().unwrap(),
        "--backend",
        "cpu",
        "--threads",
        "1",
        "--jobs",
        "2",
    ]);
    assert!(local_run.status.success(), "{}", text(&local_run.stderr));
    for name in NAMES {
        assert!(
            std::fs::read(on_slurm.join(name).join("curve.csv")).unwrap()
                == std::fs::read(local.join(name).join("curve.csv")).unwrap(),
            "curve.csv of {name} differs between the job array and the local sweep"
        );
    }
    let table = |d: &Path| std::fs::read_to_string(d.join("sweep.csv")).unwrap();
    assert_eq!(
        without_wall_clock(&table(&on_slurm)),
        without_wall_clock(&table(&local))
    );
}
