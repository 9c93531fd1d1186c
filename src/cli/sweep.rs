//! The sweep commands: `sweep` (every case here, one `--case`, or a Slurm job array with
//! `--slurm`), `sweep collect` and `sweep analyze`.

use super::args::SweepArgs;
use super::commands::in_range;
use super::progress::{interrupt_flag, mark_stopped_at_checkpoint};
use crate::job::Backend;
use crate::output::lock::lock_dir;
use crate::sweep::collect::collect;
use crate::sweep::slurm::Script;
use crate::sweep::slurm_settings::check_slurm_time;
use crate::sweep::{
    case_state, run_cases, write_case_list, Case, Outcome, RunSettings, Sweep, CASES_FILE,
};
use std::path::{Path, PathBuf};

/// The loaded sweep, its cases and where they run, for either way of running them.
struct Plan {
    spec: Sweep,
    out_dir: PathBuf,
    cases: Vec<Case>,
    backend: &'static str,
    exe: PathBuf,
}

/// Runs a sweep (all cases, or `--case`), or writes its Slurm job array (`--slurm`).
pub(super) fn sweep_command(a: SweepArgs) -> Result<(), String> {
    let file = a.sweep.as_deref().expect("clap requires the sweep file");
    let spec = Sweep::load(file).map_err(|e| e.to_string())?;
    let out_dir = spec.out_dir(a.out.as_deref());
    // Absolute, so that each case's config, log and the job script name it from anywhere.
    let out_dir =
        std::path::absolute(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let cases = spec.cases(&out_dir).map_err(|e| e.to_string())?;
    // A whole sweep owns its directory; an array task (`--case`) only its case's directory,
    // which `run_cases` locks, so the tasks of one array run side by side.
    let _lock = match a.case {
        None => Some(lock_dir(&out_dir)?),
        Some(_) => None,
    };
    let backend = match a.backend {
        Backend::Cpu => "cpu",
        Backend::Gpu => "gpu",
        Backend::Auto => "auto",
    };
    let exe = std::env::current_exe()
        .map_err(|e| format!("cannot find this program's path to run the cases with: {e}"))?;
    let plan = Plan {
        spec,
        out_dir,
        cases,
        backend,
        exe,
    };
    if a.slurm {
        write_job_array(&plan, &a)
    } else {
        run_here(&plan, &a)
    }
}

/// `--slurm`: writes the job array's script and the case list, and says how to submit.
fn write_job_array(plan: &Plan, a: &SweepArgs) -> Result<(), String> {
    let threads = in_range("--threads", a.threads.unwrap_or(1), 1, 1024)?;
    let mut settings = plan.spec.slurm.clone();
    if let Some(t) = &a.time {
        check_slurm_time(t)?;
        settings.time = t.clone();
    }
    if let Some(m) = a.mem_mb {
        in_range("--mem-mb", m as usize, 1, 16_000_000)?;
        settings.mem_mb = m;
    }
    let out_dir = &plan.out_dir;
    // A case directory that is not this sweep's is refused now, not in the tasks.
    for case in &plan.cases {
        case_state(case, &out_dir.join(&case.name))?;
    }
    let file_abs = std::path::absolute(&plan.spec.file).map_err(|e| e.to_string())?;
    write_case_list(&plan.spec, out_dir, &plan.cases)?;
    let stem = file_abs
        .file_stem()
        .map_or("sweep".into(), |s| s.to_string_lossy().into_owned());
    let script = Script {
        exe: &plan.exe,
        sweep_file: &file_abs,
        out_dir,
        cases: plan.cases.len(),
        threads,
        backend: plan.backend,
        precision: a.precision.as_str(),
        settings: &settings,
        job_name: format!("dustdem-{stem}"),
    }
    .write()?;
    println!(
        "wrote {} ({} array tasks, {} CPU{} and {} MB each, time limit {}) and {}",
        script.display(),
        plan.cases.len(),
        threads,
        if threads == 1 { "" } else { "s" },
        settings.mem_mb,
        settings.time,
        out_dir.join(CASES_FILE).display()
    );
    println!("submit: sbatch {}", script.display());
    println!("then:   dustdem sweep collect {}", out_dir.display());
    Ok(())
}

/// Runs the selected cases on this machine, collects the sweep's table after a whole sweep,
/// and reports what did not finish.
fn run_here(plan: &Plan, a: &SweepArgs) -> Result<(), String> {
    let jobs = in_range("--jobs", a.jobs.unwrap_or(1), 1, 1024)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = in_range(
        "--threads",
        a.threads.unwrap_or((cores / jobs).max(1)),
        1,
        1024,
    )?;
    let cases = &plan.cases;
    let selected = match a.case {
        Some(i) if i < cases.len() => &cases[i..=i],
        Some(i) => {
            return Err(format!(
                "--case {i}: out of range; this sweep has {} cases, 0 to {}",
                cases.len(),
                cases.len() - 1
            ))
        }
        None => &cases[..],
    };
    write_case_list(&plan.spec, &plan.out_dir, cases)?;
    let settings = RunSettings {
        jobs,
        threads,
        backend: plan.backend.to_string(),
        precision: a.precision.as_str().to_string(),
        exe: plan.exe.clone(),
    };
    let flag = interrupt_flag();
    let mut say = |line: &str| eprintln!("{line}");
    let outcome = run_cases(
        selected,
        selected.len(),
        &plan.out_dir,
        &settings,
        &flag,
        &mut say,
    )?;
    if a.case.is_none() {
        let collected = collect(&plan.out_dir)?;
        println!("wrote {}", collected.table.display());
    }
    if outcome.failed.is_empty() && !outcome.interrupted.is_empty() {
        mark_stopped_at_checkpoint();
    }
    summarise(&outcome, selected.len())
}

/// Prints how many of the `selected` cases finished; an error names the failed ones and an
/// interruption.
fn summarise(outcome: &Outcome, selected: usize) -> Result<(), String> {
    let mut problems = Vec::new();
    for (name, why) in &outcome.failed {
        problems.push(format!("{name} failed: {why}"));
    }
    if !outcome.interrupted.is_empty() || outcome.not_started > 0 {
        let stopped = outcome.interrupted.len();
        problems.push(format!(
            "interrupted ({stopped} case{} stopped at a checkpoint, {} not started); run the \
             same command again to continue",
            if stopped == 1 { "" } else { "s" },
            outcome.not_started
        ));
    }
    println!(
        "{} of {selected} case{} finished ({} now, {} before)",
        outcome.done + outcome.skipped,
        if selected == 1 { "" } else { "s" },
        outcome.done,
        outcome.skipped
    );
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("; "))
    }
}

/// `dustdem sweep collect DIR`: writes DIR/sweep.csv and names the cases that are not done.
pub(super) fn sweep_collect(dir: &Path) -> Result<(), String> {
    let collected = collect(dir)?;
    let total = collected.rows.len();
    let not_done: Vec<_> = collected.not_done().collect();
    println!(
        "wrote {}: {total} case{}, {} done",
        collected.table.display(),
        if total == 1 { "" } else { "s" },
        total - not_done.len()
    );
    if not_done.is_empty() {
        return Ok(());
    }
    for r in &not_done {
        eprintln!(
            "  {} (case {}): {}: {}",
            r.case, r.index, r.status, r.detail
        );
    }
    Err(format!(
        "{} of {total} cases are not done (listed above, with their status in {}); run the \
         sweep again (or resubmit its sweep.sbatch) to run or resume them",
        not_done.len(),
        collected.table.display()
    ))
}

/// `dustdem sweep analyze DIR`: the report of the finished cases.
pub(super) fn sweep_analyze(dir: &Path) -> Result<(), String> {
    let report = crate::sweep::analyze::analyze_dir(dir)?;
    println!("wrote {}", report.display());
    Ok(())
}
