//! `dustdem reproduce`: the results of Seizinger et al. (2012) as three sweeps (quasi-static
//! omnidirectional, dynamic omnidirectional, unidirectional), each analysed by
//! `sweep analyze`, gathered into REPRODUCTION.md beside the paper's numbers with the sizes,
//! speeds, seeds, wall-clock times and commands. Nothing here tunes the model: what comes out
//! is reported.

mod report;
mod tiers;

pub use tiers::{Study, StudyKind, Tier};

use crate::sweep::analyze::{analyze_dir, read_cases};
use crate::sweep::collect::collect;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// How to run a tier.
#[derive(Clone, Debug)]
pub struct Request {
    pub tier: Tier,
    pub out: PathBuf,
    /// Cases at once in each sweep.
    pub jobs: usize,
    /// Write Slurm job arrays instead of running.
    pub slurm: bool,
    /// Only collect, analyse and write the report (after the Slurm arrays ran).
    pub report_only: bool,
}

/// Writes each study's base config and sweep file under `out/<study>/` and returns the sweep
/// files' paths.
pub fn write_studies(tier: Tier, out: &Path) -> Result<Vec<(Study, PathBuf)>, String> {
    let mut written = Vec::new();
    for study in tier.studies() {
        let dir = out.join(study.name);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let base = dir.join("base.toml");
        let sweep = dir.join("sweep.toml");
        for (path, text) in [(&base, study.base_config()), (&sweep, study.sweep_file())] {
            crate::output::atomic::write_atomic(path, text.as_bytes())
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        written.push((study, sweep));
    }
    Ok(written)
}

/// Runs (or submits, or only reports) a tier; returns the report's path, or the job scripts'
/// directory with `slurm`.
pub fn reproduce(request: &Request) -> Result<PathBuf, String> {
    let out =
        std::path::absolute(&request.out).map_err(|e| format!("{}: {e}", request.out.display()))?;
    let studies = write_studies(request.tier, &out)?;
    let exe = std::env::current_exe()
        .map_err(|e| format!("cannot find this program's path to run the sweeps with: {e}"))?;
    let mut timings = Vec::new();
    for (study, sweep_file) in &studies {
        let runs = out.join(study.name).join("runs");
        if request.report_only {
            timings.push(None);
            continue;
        }
        let mut command = Command::new(&exe);
        command
            .arg("sweep")
            .arg(sweep_file)
            .arg("--out")
            .arg(&runs)
            .arg("--jobs")
            .arg(request.jobs.to_string());
        if request.slurm {
            command.arg("--slurm");
        }
        eprintln!("reproduce: {} ({})", study.title, study.name);
        let clock = Instant::now();
        let status = command
            .status()
            .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
        if !status.success() {
            return Err(format!(
                "the sweep of {} failed ({status}); run the same command again to resume it",
                study.name
            ));
        }
        timings.push(Some(clock.elapsed().as_secs_f64()));
    }
    if request.slurm {
        return Ok(out);
    }
    let mut analysed = Vec::new();
    for ((study, _), seconds) in studies.into_iter().zip(timings) {
        let runs = out.join(study.name).join("runs");
        analyze_dir(&runs)?;
        let (cases, _) = read_cases(&runs)?;
        let case_seconds = collect(&runs)?
            .rows
            .iter()
            .filter_map(|r| r.record.as_ref().map(|c| c.wall_clock_s))
            .collect();
        analysed.push(report::Analysed {
            study,
            runs,
            cases,
            seconds,
            case_seconds,
        });
    }
    let path = out.join("REPRODUCTION.md");
    let text = report::markdown(request, &analysed);
    crate::output::atomic::write_atomic(&path, text.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}
