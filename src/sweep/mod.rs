//! Parameter sweeps: the cartesian product of wall speeds, seeds, model variants and sample
//! sizes, each case an ordinary run directory with its own `config.toml`, run by the same
//! binary as a child process (`dustdem run`, or `dustdem resume` of its checkpoint), a few at
//! a time; or exported as a Slurm job array; and collected into one table.
//!
//! Here: the case list and the runner; `status` reads what state a case directory is in and
//! its status file; `spec` reads the sweep file (`axes` checks its axes and variants), `cases` expands
//! it into cases, `slurm` writes the job-array script, `collect` the table.
//!
//! A case directory is locked (`output::lock`) from the moment its attempt is prepared until its
//! end is recorded, and the child runs under that lock; the sweep's own directory is locked by a
//! whole sweep, not by an array task (`--case`), so tasks of one array run side by side.
//!
//! A case directory holds, besides what a run writes, `sweep-status.toml` (written atomically:
//! `running` when an attempt starts, then `done`, `failed` or `interrupted` when it ends) and
//! `sweep.log` (what each attempt printed). A case counts as finished only when its status says
//! `done` for the run id the directory's `run.id` holds: a run started by hand in the directory
//! since then (`dustdem run --force`) makes the case unfinished again.

pub mod analyze;
mod attempt;
mod axes;
mod cases;
pub mod collect;
pub mod slurm;
pub mod slurm_settings;
pub mod spec;
mod status;

pub use attempt::last_row;
use attempt::{conclude, terminate};
pub use spec::{Case, Sweep};
pub use status::{case_state, CaseState, CaseStatus};

use crate::job::load_checkpoint;
use crate::output::atomic::write_atomic;
use crate::output::lock::{lock_dir, Lock, HANDED_LOCK_ENV};
use crate::output::run_dir::{read_run_id, CONFIG_FILE, CURVE_FILE};
use std::fs::{self, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A case's status file, beside its run's outputs.
pub const STATUS_FILE: &str = "sweep-status.toml";
/// What the attempts at a case printed (appended, one header line per attempt).
pub const LOG_FILE: &str = "sweep.log";
/// The list of cases, in the sweep's output directory.
pub const CASES_FILE: &str = "cases.csv";
/// The merged table `collect` writes into the sweep's output directory.
pub const TABLE_FILE: &str = "sweep.csv";
/// The Slurm job-array script, in the sweep's output directory.
pub const SBATCH_FILE: &str = "sweep.sbatch";

/// Writes the list of cases (`cases.csv`) into the sweep's output directory.
pub fn write_case_list(sweep: &Sweep, out_dir: &Path, cases: &[Case]) -> Result<(), String> {
    fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let mut text = format!(
        "# dustdem sweep of {} (base config {}): {} cases, one directory each\n\
         index,case,wall_speed_m_s,seed,variant,monomers\n",
        std::path::absolute(&sweep.file)
            .unwrap_or_else(|_| sweep.file.clone())
            .display(),
        sweep.base_path.display(),
        cases.len()
    );
    for c in cases {
        text.push_str(&format!(
            "{},{},{},{},{},{}\n",
            c.index, c.name, c.wall_speed, c.seed, c.variant, c.monomers
        ));
    }
    let path = out_dir.join(CASES_FILE);
    // Array tasks write the same bytes at once: each renames its own complete file over it.
    write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
}

/// How the cases run.
pub struct RunSettings {
    /// Cases at once.
    pub jobs: usize,
    /// Threads of each case's CPU engine.
    pub threads: usize,
    /// `--backend` of each case's run.
    pub backend: String,
    /// `--precision` of each case's run.
    pub precision: String,
    /// The binary each case runs (this one).
    pub exe: PathBuf,
}

/// What a sweep's cases came to.
#[derive(Debug, Default)]
pub struct Outcome {
    pub done: usize,
    pub skipped: usize,
    /// Case names with what went wrong.
    pub failed: Vec<(String, String)>,
    pub interrupted: Vec<String>,
    /// Cases not started because the sweep was interrupted first.
    pub not_started: usize,
}

/// One attempt running.
struct Attempt {
    index: usize,
    pid: u32,
    started: Instant,
    log_offset: u64,
    resumed_from_step: Option<u64>,
    previous: Option<CaseStatus>,
    /// The case directory's lock, handed to the child; released once the attempt is recorded.
    _lock: Lock,
}

/// What [`launch`] did with a case.
enum Launched {
    Started(Box<Attempt>),
    /// Found finished once its directory was locked (another process ran it meanwhile).
    Finished,
}

/// Runs `cases` (whose directories are `out_dir/<name>`), at most `settings.jobs` at once,
/// each as a child process of `settings.exe`: finished cases are skipped, cases with a
/// checkpoint resumed, the others run from the start. `interrupt` (SIGINT/SIGTERM) stops
/// launching; the running cases get SIGTERM, so they checkpoint and stop, and are recorded as
/// interrupted. Progress lines go to `say`.
pub fn run_cases(
    cases: &[Case],
    total: usize,
    out_dir: &Path,
    settings: &RunSettings,
    interrupt: &AtomicBool,
    say: &mut dyn FnMut(&str),
) -> Result<Outcome, String> {
    // Every case's state is read before anything runs: a conflict stops the sweep untouched.
    let mut pending = Vec::new();
    let mut outcome = Outcome::default();
    let (mut to_resume, mut to_run) = (0, 0);
    for case in cases {
        let dir = out_dir.join(&case.name);
        match case_state(case, &dir)? {
            CaseState::Done(_) => outcome.skipped += 1,
            state => {
                if matches!(state, CaseState::Resume(_)) {
                    to_resume += 1;
                } else {
                    to_run += 1;
                }
                pending.push(case);
            }
        }
    }
    say(&format!(
        "sweep: {} case{} in {}: {} finished (skipped), {to_resume} to resume, {to_run} to run; \
         {} at once, {} thread{} each",
        cases.len(),
        if cases.len() == 1 { "" } else { "s" },
        out_dir.display(),
        outcome.skipped,
        settings.jobs,
        settings.threads,
        if settings.threads == 1 { "" } else { "s" },
    ));
    let finished_before = total - cases.len() + outcome.skipped;
    let mut finished = finished_before;
    let (tx, rx) = mpsc::channel::<(usize, std::io::Result<ExitStatus>)>();
    let mut running: Vec<Attempt> = Vec::new();
    let mut queue: Vec<_> = pending.into_iter().rev().collect();
    let mut forwarded = false;
    loop {
        let stop = interrupt.load(Ordering::SeqCst);
        if stop && !forwarded {
            for a in &running {
                terminate(a.pid);
            }
            forwarded = true;
            if !queue.is_empty() {
                say(&format!(
                    "sweep: interrupted; {} running case{} checkpoint and stop, {} not started",
                    running.len(),
                    if running.len() == 1 { "" } else { "s" },
                    queue.len()
                ));
            }
        }
        while !stop && running.len() < settings.jobs {
            let Some(case) = queue.pop() else {
                break;
            };
            let dir = out_dir.join(&case.name);
            match launch(case, &dir, settings, &tx) {
                Ok(Launched::Finished) => {
                    finished += 1;
                    outcome.skipped += 1;
                    say(&format!(
                        "sweep [{finished}/{total}] {} finished meanwhile (skipped)",
                        case.name
                    ));
                }
                Ok(Launched::Started(attempt)) => {
                    say(&match attempt.resumed_from_step {
                        Some(step) => format!(
                            "sweep [{finished}/{total}] resuming {} from step {step}",
                            case.name
                        ),
                        None => format!("sweep [{finished}/{total}] started {}", case.name),
                    });
                    running.push(*attempt);
                }
                Err(e) => {
                    say(&format!(
                        "sweep [{finished}/{total}] FAILED {}: {e}",
                        case.name
                    ));
                    outcome.failed.push((case.name.clone(), e));
                }
            }
        }
        if running.is_empty() && (queue.is_empty() || stop) {
            outcome.not_started = queue.len();
            break;
        }
        let Ok((index, status)) = rx.recv_timeout(Duration::from_millis(200)) else {
            continue;
        };
        let k = running
            .iter()
            .position(|a| a.index == index)
            .expect("a running case reported");
        let attempt = running.swap_remove(k);
        let case = cases
            .iter()
            .find(|c| c.index == index)
            .expect("a case of this sweep");
        let dir = out_dir.join(&case.name);
        let status = status.map_err(|e| format!("waiting for case {}: {e}", case.name))?;
        let record = conclude(
            case,
            &dir,
            &attempt,
            status,
            interrupt.load(Ordering::SeqCst),
        );
        record.write(&dir)?;
        let seconds = attempt.started.elapsed().as_secs_f64();
        match record.status.as_str() {
            "done" => {
                finished += 1;
                outcome.done += 1;
                say(&format!(
                    "sweep [{finished}/{total}] done {} in {seconds:.1} s: phi {:.4}, P {:.4e} Pa \
                     ({})",
                    case.name,
                    record.final_phi.unwrap_or(f64::NAN),
                    record.final_pressure_pa.unwrap_or(f64::NAN),
                    record.stop
                ));
            }
            "interrupted" => {
                say(&format!(
                    "sweep [{finished}/{total}] interrupted {} after {seconds:.1} s: {}",
                    case.name, record.message
                ));
                outcome.interrupted.push(case.name.clone());
            }
            _ => {
                say(&format!(
                    "sweep [{finished}/{total}] FAILED {} after {seconds:.1} s: {} (log: {})",
                    case.name,
                    record.message,
                    dir.join(LOG_FILE).display()
                ));
                outcome
                    .failed
                    .push((case.name.clone(), record.message.clone()));
            }
        }
    }
    Ok(outcome)
}

/// Locks a case's directory, prepares it and starts its attempt (`run`, or `resume` of its
/// checkpoint) as a child whose output goes to the case's log; a waiter thread reports its
/// exit on `tx`. The child works under the sweep's lock of the directory (the lock's token in
/// its environment), so nothing else writes there from before the status says `running` until
/// the attempt's end is recorded. The case's state is read under the lock: what the sweep read
/// at its start may be out of date (an array task may have run the case since).
fn launch(
    case: &Case,
    dir: &Path,
    settings: &RunSettings,
    tx: &mpsc::Sender<(usize, std::io::Result<ExitStatus>)>,
) -> Result<Launched, String> {
    let at = |p: &Path| {
        let p = p.to_path_buf();
        move |e: std::io::Error| format!("{}: {e}", p.display())
    };
    let mut lock = lock_dir(dir)?;
    let state = match case_state(case, dir)? {
        CaseState::Done(_) => return Ok(Launched::Finished),
        state => state,
    };
    fs::create_dir_all(dir).map_err(at(dir))?;
    let config_path = dir.join(CONFIG_FILE);
    if fs::read_to_string(&config_path).ok().as_deref() != Some(case.config_text.as_str()) {
        write_atomic(&config_path, case.config_text.as_bytes()).map_err(at(&config_path))?;
    }
    let previous = CaseStatus::read(dir);
    let mut args: Vec<String> = Vec::new();
    let mut resumed_from_step = None;
    match &state {
        CaseState::Resume(checkpoint) => {
            resumed_from_step = load_checkpoint(checkpoint).ok().map(|c| c.run.engine.step);
            args.extend(["resume".into(), checkpoint.display().to_string()]);
        }
        CaseState::Fresh { replace } => {
            args.extend([
                "run".into(),
                config_path.display().to_string(),
                "--out".into(),
                dir.display().to_string(),
            ]);
            if *replace {
                args.push("--force".into());
            }
        }
        CaseState::Done(_) => unreachable!("finished cases are not launched"),
    }
    args.extend([
        "--backend".into(),
        settings.backend.clone(),
        "--precision".into(),
        settings.precision.clone(),
        "--threads".into(),
        settings.threads.to_string(),
        "--quiet".into(),
    ]);
    let attempts = previous.as_ref().map_or(0, |p| p.attempts) + 1;
    CaseStatus {
        case: case.name.clone(),
        status: "running".into(),
        run_id: read_run_id(dir).unwrap_or_default(),
        attempts,
        wall_clock_s: previous.as_ref().map_or(0.0, |p| p.wall_clock_s),
        resumed_from_step,
        message: format!("started by process {}", std::process::id()),
        ..CaseStatus::default()
    }
    .write(dir)?;
    let log_path = dir.join(LOG_FILE);
    let mut log = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .map_err(at(&log_path))?;
    writeln!(
        log,
        "## attempt {attempts}: {} {}",
        settings.exe.display(),
        args.join(" ")
    )
    .map_err(at(&log_path))?;
    let log_offset = log.seek(SeekFrom::End(0)).map_err(at(&log_path))?;
    let err_log = log.try_clone().map_err(at(&log_path))?;
    let mut child = Command::new(&settings.exe)
        .args(&args)
        .env(HANDED_LOCK_ENV, lock.token())
        .stdin(Stdio::null())
        .stdout(Stdio::from(log))
        .stderr(Stdio::from(err_log))
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", settings.exe.display()))?;
    let pid = child.id();
    // The lock names the child too, so a sweep killed outright leaves its running case locked
    // (where that cannot be recorded, the lock still names the sweep).
    let _ = lock.hand_to(pid);
    let tx = tx.clone();
    let index = case.index;
    std::thread::spawn(move || {
        let status = child.wait();
        let _ = tx.send((index, status));
    });
    Ok(Launched::Started(Box::new(Attempt {
        index,
        pid,
        started: Instant::now(),
        log_offset,
        resumed_from_step,
        previous,
        _lock: lock,
    })))
}
