//! `dustdem calibrate --slurm` on a real single-node Slurm started on localhost: every batch
//! of runs becomes a job array over the run cache (one run per task), the calibration goes on
//! when it finishes, and the report, the figure and the corrected config are byte-identical to
//! a local calibration's. A second calibration over the filled cache submits nothing. The data:
//! a sticking velocity synthesized with stronger damping (cheap runs, so the test is about the
//! arrays, not the physics; `tests/calibrate/` holds the physics).

mod common;

use common::slurm::{slurm_available, LocalSlurm};
use common::Scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The sticking velocity of `configs/calibrate_quick.toml` with 1.5 × its viscous damping.
const DATA: &str = "[source]\ncitation = \"synthetic\"\nwhat = \"one sticking velocity\"\n\n\
                    [[sticking]]\nname = \"sticking (synthetic)\"\nvelocity_m_s = 0.6612815190507568\n\
                    sigma_m_s = 0.03501667656703096\n";

fn calibrate(dir: &Path, out: &str, cache: Option<&str>, slurm: Option<&LocalSlurm>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_dustdem"));
    c.arg("calibrate");
    if let Some(s) = slurm {
        // The cluster's config, for the sbatch the calibration calls.
        c.env("SLURM_CONF", s.conf());
    }
    if let Some(cache) = cache {
        c.args(["--cache", cache]);
    }
    c.current_dir(dir).args([
        "--measured",
        "sticking.toml",
        "--config",
        repo("configs/calibrate_quick.toml").to_str().unwrap(),
        "--out",
        out,
        "--rounds",
        "1",
        "--threads",
        "2",
    ]);
    if slurm.is_some() {
        c.args(["--slurm", "--slurm-time", "10", "--slurm-mem-mb", "500"]);
    }
    c.output().unwrap()
}

#[test]
fn a_calibration_on_slurm_job_arrays_writes_the_local_calibrations_report() {
    if !slurm_available() {
        return;
    }
    let dir = Scratch::new("calibrate-slurm");
    std::fs::write(dir.join("sticking.toml"), DATA).unwrap();
    let local = calibrate(&dir, "local", None, None);
    assert!(local.status.success(), "{}", text(&local.stderr));

    let started = Instant::now();
    let slurm = LocalSlurm::start(&dir.join("slurm"));
    let on_slurm = calibrate(&dir, "on_slurm", None, Some(&slurm));
    let seconds = started.elapsed().as_secs_f64();
    let err = text(&on_slurm.stderr);
    assert!(on_slurm.status.success(), "{err}{}", slurm.logs());
    let arrays = err.matches("as a job array").count();
    let batches = std::fs::read_dir(dir.join("on_slurm/run_cache/slurm"))
        .unwrap()
        .count();
    let tasks: usize = std::fs::read_dir(dir.join("on_slurm/run_cache/slurm"))
        .unwrap()
        .map(|b| {
            std::fs::read_dir(b.unwrap().path())
                .unwrap()
                .filter(|f| {
                    f.as_ref()
                        .unwrap()
                        .path()
                        .extension()
                        .is_some_and(|e| e == "key")
                })
                .count()
        })
        .sum();
    eprintln!("calibrate --slurm: {arrays} job arrays, {tasks} tasks, {seconds:.1} s");
    assert!(arrays >= 2 && arrays == batches, "{err}");
    for file in ["report.md", "calibration.png", "corrected.toml"] {
        let (a, b) = (
            std::fs::read(dir.join("local").join(file)).unwrap(),
            std::fs::read(dir.join("on_slurm").join(file)).unwrap(),
        );
        assert!(a == b, "{file} differs from the local calibration's");
    }
    // Every run the local calibration made was made by an array task and stored.
    let entries = |d: &str| {
        let mut names: Vec<String> = std::fs::read_dir(dir.join(d).join("run_cache"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".run"))
            .collect();
        names.sort();
        names
    };
    assert_eq!(entries("local"), entries("on_slurm"));
    assert_eq!(tasks, entries("on_slurm").len(), "one task per run");

    // Again over the filled cache: nothing left to submit.
    let again = calibrate(&dir, "again", Some("on_slurm/run_cache"), Some(&slurm));
    let again_err = text(&again.stderr);
    assert!(again.status.success(), "{again_err}");
    assert!(!again_err.contains("as a job array"), "{again_err}");
    let report = |d: &str| std::fs::read(dir.join(d).join("report.md")).unwrap();
    assert!(report("again") == report("local"));
    drop(slurm);
}
