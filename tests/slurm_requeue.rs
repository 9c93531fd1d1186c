//! A Slurm time limit survived, on a real single-node Slurm started on localhost: an array
//! task whose limit (2 minutes) is shorter than its run gets Slurm's early warning, checkpoints,
//! exits with the resumable status, is requeued by its script and resumes from the
//! checkpoint until the case is done; its curve and profiles are byte-identical to the same
//! case run without interruption. Alone in its test binary, so that the timings are not
//! squeezed by other tests.

mod common;

use common::slurm::{slurm_available, LocalSlurm};
use common::Scratch;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn dustdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// 1000 RBD monomers pushed at 0.06 m/s up to φ = 0.5: about a million steps, near three
/// minutes of one core of a 2-core AMD EPYC test machine (at 0.15 m/s the faster corrections
/// brought it to 68 s, inside the limit), so that a 2-minute limit cuts it at least once: the warning, asked for 30 s ahead, comes 30 to 90 s ahead (Slurm may send it up to
/// 60 s early), after 30 to 90 s of work.
const BASE: &str = "[sample]\nmonomers = 1000\nseed = 1\n[experiment]\nwall_speed_m_s = 0.06\n\
                    phi_stop = 0.5\naverage_steps = 100\n[output]\nsnapshot_format = \"none\"\n";

/// One case; a 2-minute limit with the warning 30 s before it.
const SWEEP: &str = "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [0.06]\nseed = [1]\n\
                     monomers = [1000]\n[slurm]\ntime = \"2\"\nsignal_lead_s = 30\nmem_mb = 500\n";

const CASE: &str = "v0.06_seed1_base_n1000";

fn status_field(dir: &Path, key: &str) -> String {
    let text = std::fs::read_to_string(dir.join("sweep-status.toml")).unwrap();
    let table: toml::Table = text.parse().unwrap();
    table[key].to_string()
}

fn succeeded(out: &Output) -> bool {
    out.status.success()
}

#[test]
fn a_task_cut_by_its_time_limit_is_requeued_and_finishes_as_an_uninterrupted_run() {
    if !slurm_available() {
        return;
    }
    let dir = Scratch::new("slurm-requeue");
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let sweep = dir.join("sweep.toml");
    std::fs::write(&sweep, SWEEP).unwrap();
    let (on_slurm, local) = (dir.join("on_slurm"), dir.join("local"));
    let export = dustdem()
        .args(["sweep", sweep.to_str().unwrap(), "--out"])
        .arg(&on_slurm)
        .args(["--backend", "cpu", "--threads", "1", "--slurm"])
        .output()
        .unwrap();
    assert!(succeeded(&export), "{}", text(&export.stderr));
    let script_path = on_slurm.join("sweep.sbatch");
    let script = std::fs::read_to_string(&script_path).unwrap();
    for line in [
        "#SBATCH --time=2\n",
        "#SBATCH --signal=B:USR1@30\n",
        "#SBATCH --requeue\n",
        "#SBATCH --open-mode=append\n",
    ] {
        assert!(script.contains(line), "{line} in:\n{script}");
    }
    let names = std::fs::read_to_string(on_slurm.join("cases.csv")).unwrap();
    assert!(names.contains(CASE), "{names}");

    // The uninterrupted run, on the other core, while Slurm runs its copy.
    let reference = dustdem()
        .args(["sweep", sweep.to_str().unwrap(), "--out"])
        .arg(&local)
        .args(["--backend", "cpu", "--threads", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();

    let started = Instant::now();
    let mut slurm = LocalSlurm::start(&dir.join("slurm"));
    let job = slurm.submit(&script_path, &dir);
    slurm.wait(&job, Duration::from_secs(900));
    let finished = started.elapsed();
    drop(slurm);
    let reference = reference.wait_with_output().unwrap();
    assert!(succeeded(&reference), "{}", text(&reference.stderr));

    let case = on_slurm.join(CASE);
    let logs: String = std::fs::read_dir(on_slurm.join("slurm"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .collect();
    let attempts: u64 = status_field(&case, "attempts").parse().unwrap();
    let requeues = logs.matches("requeueing task").count();
    eprintln!(
        "slurm: {attempts} attempts, {requeues} requeues, done {:.1} s after the daemons' start",
        finished.as_secs_f64()
    );
    assert_eq!(
        status_field(&case, "status"),
        "\"done\"",
        "task log:\n{logs}"
    );
    assert!(
        attempts >= 2 && requeues >= 1,
        "the limit should have cut the run at least once: {attempts} attempts, {requeues} \
         requeues; task log:\n{logs}"
    );
    assert_eq!(
        requeues as u64,
        attempts - 1,
        "every attempt but the last ends in a requeue; task log:\n{logs}"
    );
    for file in ["curve.csv", "profiles.csv"] {
        let (a, b) = (
            std::fs::read(case.join(file)).unwrap(),
            std::fs::read(local.join(CASE).join(file)).unwrap(),
        );
        assert!(a == b, "{file} differs from the uninterrupted run's");
    }
}
