//! `dustdem reproduce`: the results of Seizinger et al. (2012) as four sweeps (quasi-static
//! omnidirectional, dynamic omnidirectional at and below 1 m/s, unidirectional). What
//! finished is kept in the tier's store (compact curves and profiles, meant to be
//! committed), analysed the paper's way and written to REPRODUCTION.md as a table of
//! verdicts on the paper's claims. Nothing here tunes the model: what comes out is reported.

mod analysis;
mod claims;
mod claims_curves;
mod claims_dynamic;
mod figures;
#[cfg(test)]
mod fixtures;
mod laws;
mod report;
mod size_trend;
pub mod store;
mod tiers;
mod verdicts;
mod why;

pub use tiers::{Study, StudyKind, Tier, Variant, CALIBRATED, UNMODIFIED};

use std::path::{Path, PathBuf};
use std::process::Command;

/// How to run a tier.
#[derive(Clone, Debug)]
pub struct Request {
    pub tier: Tier,
    /// The tier's directory: study files, the store of finished cases, the report.
    pub out: PathBuf,
    /// Where the sweeps run (checkpoints, full outputs): `<runs>/<study>`; default
    /// `<out>/<study>/runs`.
    pub runs: Option<PathBuf>,
    /// Cases at once in each sweep.
    pub jobs: usize,
    /// Write Slurm job arrays instead of running.
    pub slurm: bool,
    /// Only store what finished and write the report (after the Slurm arrays ran).
    pub report_only: bool,
}

impl Request {
    fn runs_of(&self, out: &Path, study: &Study) -> PathBuf {
        match &self.runs {
            Some(r) => r.join(study.name),
            None => out.join(study.name).join("runs"),
        }
    }
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

fn run_sweep(
    request: &Request,
    study: &Study,
    sweep_file: &Path,
    runs: &Path,
) -> Result<(), String> {
    let exe = std::env::current_exe()
        .map_err(|e| format!("cannot find this program's path to run the sweeps with: {e}"))?;
    let mut command = Command::new(&exe);
    command
        .arg("sweep")
        .arg(sweep_file)
        .arg("--out")
        .arg(runs)
        .arg("--jobs")
        .arg(request.jobs.to_string());
    if request.slurm {
        command.arg("--slurm");
    }
    eprintln!("reproduce: {} ({})", study.title, study.name);
    let status = command
        .status()
        .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
    if !status.success() {
        return Err(format!(
            "the sweep of {} failed ({status}); run the same command again to resume it",
            study.name
        ));
    }
    Ok(())
}

/// Runs (or submits, or only reports) a tier; returns the report's path, or the job scripts'
/// directory with `slurm`. Finished cases are added to the tier's store, and the report is
/// written from the store alone.
pub fn reproduce(request: &Request) -> Result<PathBuf, String> {
    let out =
        std::path::absolute(&request.out).map_err(|e| format!("{}: {e}", request.out.display()))?;
    let studies = write_studies(request.tier, &out)?;
    let machine = crate::bench::host();
    let mut analysed = Vec::new();
    for (study, sweep_file) in studies {
        let runs = request.runs_of(&out, &study);
        if !request.report_only {
            run_sweep(request, &study, &sweep_file, &runs)?;
        }
        if request.slurm {
            continue;
        }
        let store_dir = out.join(study.name);
        if runs.join(crate::sweep::CASES_FILE).exists() {
            let added = store::harvest(&runs, &store_dir, &machine)?;
            if added > 0 {
                eprintln!(
                    "reproduce: {added} finished case(s) of {} stored",
                    study.name
                );
            }
        }
        let cases = store::read_store(&store_dir)?;
        let order: Vec<&str> = study.variants.iter().map(|v| v.name).collect();
        let families = analysis::analyse(study.kind, &cases, &order);
        analysed.push(report::Analysed {
            study,
            cases,
            families,
        });
    }
    if request.slurm {
        return Ok(out);
    }
    let speed_figures = figures::write_figures(&analysed, &out.join("figures"))?;
    let path = out.join("REPRODUCTION.md");
    let text = report::markdown(
        request.tier,
        &analysed,
        report::store_size(&out),
        &speed_figures,
    );
    crate::output::atomic::write_atomic(&path, text.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}
