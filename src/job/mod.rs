//! Running a configured job end to end: set up (or resume), simulate, write the curve,
//! profiles, checkpoints, the effective config and a plot into the output directory.
//!
//! The job is where a backend is chosen (`backend`): everything it calls is written against
//! the engine contract. Here: fresh and resumed compressions and the loop that reports their
//! rows; `checkpoint` (checkpoint bodies, reading one back, the failed state),
//! `collision` (the head-on collision job) and `figure` (the curve plot with its measured
//! reference).

mod backend;
mod checkpoint;
mod collision;
pub(crate) mod figure;
mod progress;

pub use backend::{gpu_report, reference_engine, Backend, PrecisionChoice, PrivateRuntimeDir};
pub use checkpoint::{load_checkpoint, LoadedCheckpoint};
pub use figure::{curve_plot, BLUM_SCHRAEPLER_2004_UNI, GUETTLER_2009_OMNI};
use progress::fraction_done;
pub use progress::Progress;

use crate::backend::cpu::CpuEngine;
use crate::backend::gpu::engine::GpuEngine;
use crate::config::{Config, ExperimentKind};
use crate::engine::{Engine, EngineError};
use crate::experiment::compression::{Compression, Event, Row, RunError, StopReason};
use crate::output::atomic::remove_stale_temporaries;
use crate::output::checkpoint::write_checkpoint;
use crate::output::csv::{read_csv, CsvWriter};
use crate::output::lock::lock_dir;
use crate::output::run_dir::{
    check_resumable, new_run_id, NewRunDir, RunDir, CONFIG_FILE, PLOT_FILE,
};
use crate::output::snapshot::series::write_snapshot;
use crate::state::State;
use backend::choose_backend;
use checkpoint::{checkpoint_body, keep_failed_state};
use collision::run_collision;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The built-in default job: a small omnidirectional compression.
pub const DEFAULT_CONFIG: &str = include_str!("../../configs/omni_quick.toml");

pub use crate::output::run_dir::{CHECKPOINT_FILE, CURVE_FILE, PROFILE_FILE};
const PROFILE_HEADER: [&str; 5] = ["step", "time_s", "phi_mean", "z_um", "phi"];

/// What a finished job produced.
pub struct JobSummary {
    pub out_dir: PathBuf,
    pub files: Vec<PathBuf>,
    pub lines: Vec<String>,
}

/// How a job reports, where it runs and when it stops early.
pub struct JobOptions<'a> {
    pub progress: &'a mut dyn FnMut(&Progress),
    /// Set by a signal handler: checkpoint at the next row and stop.
    pub interrupt: Option<&'a AtomicBool>,
    pub backend: Backend,
    /// The arithmetic of a GPU engine (ignored on the CPU).
    pub precision: PrecisionChoice,
    /// Receives one line naming the backend chosen, and one per checkpoint (size, seconds).
    pub notice: &'a mut dyn FnMut(&str),
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> RunError + '_ {
    move |e| RunError::Output(format!("{}: {e}", path.display()))
}

/// Runs `config`, writing into `out_dir`. A directory another process writes into (its lock,
/// `output::lock`) is refused, `replace` or not. A directory holding the results of an earlier
/// run is refused, unless `replace`: then those results (only files dustdem writes) are removed
/// once the new run is set up. Everything that can fail in the setup (sample, walls, engine) is
/// done before the directory is touched; if writing the first files fails, they are removed.
pub fn run_job(
    config: &Config,
    out_dir: &Path,
    replace: bool,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    // Held until the job returns, whatever it returns (an interrupt included).
    let _lock = lock_dir(out_dir).map_err(RunError::Output)?;
    let fresh = NewRunDir::check(out_dir, replace).map_err(RunError::Output)?;
    let effective = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    match config.experiment.kind {
        ExperimentKind::Collision => run_collision(config, fresh, &effective),
        _ => match choose_backend(options)? {
            None => start(
                config,
                fresh,
                &effective,
                Compression::with_engine(config, reference_engine)?,
                options,
            ),
            Some(ctx) => {
                let run = Compression::with_engine(config, |law, dt, m, walls, ps, ws| {
                    Ok(GpuEngine::new(ctx, law, dt, m, walls, ps, ws)?)
                })?;
                start(config, fresh, &effective, run, options)
            }
        },
    }
}

/// Creates the directory of a run that is set up: its id, effective config and what `write`
/// writes. If anything fails, the run leaves nothing behind.
fn create_run_dir<T>(
    fresh: NewRunDir,
    effective: &str,
    write: impl FnOnce(&RunDir) -> Result<T, RunError>,
) -> Result<(RunDir, T), RunError> {
    let run_id = new_run_id(effective, fresh.dir());
    let dir = fresh.create(&run_id, effective).map_err(RunError::Output)?;
    match write(&dir) {
        Ok(written) => Ok((dir, written)),
        Err(e) => {
            dir.discard();
            Err(e)
        }
    }
}

/// Creates the run directory with the output tables and the first snapshot of a fresh
/// compression, then runs it.
fn start<E: Engine>(
    config: &Config,
    fresh: NewRunDir,
    effective: &str,
    run: Compression<E>,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    let (dir, (curve, profiles)) = create_run_dir(fresh, effective, |dir| {
        let curve_path = dir.dir.join(CURVE_FILE);
        let mut curve =
            CsvWriter::create(&curve_path, &Row::HEADER).map_err(io_err(&curve_path))?;
        curve
            .comment(&describe_run(config, &run))
            .map_err(io_err(&curve_path))?;
        let profile_path = dir.dir.join(PROFILE_FILE);
        let profiles =
            CsvWriter::create(&profile_path, &PROFILE_HEADER).map_err(io_err(&profile_path))?;
        write_snapshot(
            &dir.dir,
            config.output.snapshot_format,
            &run.engine.state(),
            "",
        )
        .map_err(io_err(&dir.dir))?;
        Ok((curve, profiles))
    })?;
    drive(config, &dir.dir, &dir.run_id, run, curve, profiles, options)
}

/// Continues the run a checkpoint belongs to, in the directory that holds the checkpoint (locked
/// for the whole resume): once that directory's run id and the curve and profile files are checked
/// to be the ones the checkpoint recorded (before any file is changed), those files are cut back to
/// what they held at the checkpoint, then appended to. The run continues on the backend the options
/// choose; on the backend that wrote the checkpoint it continues bit for bit.
pub fn resume_job(checkpoint: &Path, options: &mut JobOptions) -> Result<JobSummary, RunError> {
    let loaded = load_checkpoint(checkpoint)?;
    let _lock = lock_dir(&loaded.out_dir).map_err(RunError::Output)?;
    // A run killed outright (SIGKILL, a node lost) may have been writing a file.
    let stale = remove_stale_temporaries(&loaded.out_dir).map_err(io_err(&loaded.out_dir))?;
    for path in stale {
        (options.notice)(&format!(
            "removed {}, left by a writer that was killed while writing it",
            path.display()
        ));
    }
    check_resumable(
        &loaded.out_dir,
        checkpoint,
        &loaded.run_id,
        &[
            (CURVE_FILE, loaded.curve_len, loaded.curve_hash),
            (PROFILE_FILE, loaded.profile_len, loaded.profile_hash),
        ],
    )
    .map_err(RunError::Output)?;
    match choose_backend(options)? {
        None => continue_job(
            loaded,
            |run| run.map_engine(|state| Ok(CpuEngine::from_state(state))),
            options,
        ),
        Some(ctx) => continue_job(
            loaded,
            |run| run.map_engine(|state| Ok(GpuEngine::resume(ctx, &state)?)),
            options,
        ),
    }
}

/// Reopens a checkpoint's outputs and drives its run on the engine `engine` makes of it.
fn continue_job<E: Engine>(
    loaded: LoadedCheckpoint,
    engine: impl FnOnce(Compression<State>) -> Result<Compression<E>, RunError>,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    let run = engine(loaded.run)?;
    let out_dir = loaded.out_dir;
    let curve_path = out_dir.join(CURVE_FILE);
    let curve = CsvWriter::reopen(
        &curve_path,
        Row::HEADER.len(),
        loaded.curve_len,
        loaded.curve_hash,
    )
    .map_err(io_err(&curve_path))?;
    let profile_path = out_dir.join(PROFILE_FILE);
    let profiles = CsvWriter::reopen(
        &profile_path,
        PROFILE_HEADER.len(),
        loaded.profile_len,
        loaded.profile_hash,
    )
    .map_err(io_err(&profile_path))?;
    drive(
        &loaded.config,
        &out_dir,
        &loaded.run_id,
        run,
        curve,
        profiles,
        options,
    )
}

fn describe_run<E: Engine>(config: &Config, run: &Compression<E>) -> String {
    format!(
        "dustdem {} compression, {} monomers, wall speed {} m/s, dt {} ns, seed {}",
        if run.kind == ExperimentKind::Omni {
            "omnidirectional"
        } else {
            "unidirectional"
        },
        run.engine.monomer_count(),
        config.experiment.wall_speed_m_s,
        config.integration.dt_ns,
        config.sample.seed
    )
}

/// The compression loop shared by fresh and resumed runs.
fn drive<E: Engine>(
    config: &Config,
    out_dir: &Path,
    run_id: &str,
    mut run: Compression<E>,
    mut curve: CsvWriter,
    mut profiles: CsvWriter,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    let curve_path = out_dir.join(CURVE_FILE);
    let profile_path = out_dir.join(PROFILE_FILE);
    let checkpoint_path = out_dir.join(CHECKPOINT_FILE);
    let every_rows = config.output.checkpoint_every_rows;
    let every_seconds = config.output.checkpoint_minutes * 60.0;
    let started = Instant::now();
    let start_step = run.engine.step_count();
    let mut last_checkpoint = Instant::now();
    let mut rows_since_checkpoint = 0u64;
    let mut rows_since_snapshot = 0u64;
    let snapshot_every = config.output.snapshot_every_rows;
    let snapshot_format = config.output.snapshot_format;
    let e = &config.experiment;
    let (phi_stop, max_steps) = (e.phi_stop, e.max_steps);
    let wall_speed = e.wall_speed_m_s * 100.0;
    let progress = &mut options.progress;
    let notice = &mut options.notice;
    let interrupt = options.interrupt;
    let stop = run.run(&mut |event| match event {
        Event::Row(row) => {
            curve
                .write_row(&row.values())
                .map_err(io_err(&curve_path))?;
            let elapsed = started.elapsed().as_secs_f64().max(1e-9);
            progress(&Progress {
                row,
                fraction: fraction_done(row, wall_speed, phi_stop, max_steps),
                steps_per_second: (row.step - start_step) as f64 / elapsed,
            });
            rows_since_checkpoint += 1;
            rows_since_snapshot += 1;
            Ok(())
        }
        Event::Profile(row, slabs) => {
            for (z, phi) in slabs {
                profiles
                    .write_row(&[row.step as f64, row.time, row.phi, z * 1e4, *phi])
                    .map_err(io_err(&profile_path))?;
            }
            Ok(())
        }
        Event::RowDone(state) => {
            if snapshot_every > 0 && rows_since_snapshot >= snapshot_every {
                write_snapshot(out_dir, snapshot_format, &state.engine.state(), "")
                    .map_err(io_err(out_dir))?;
                rows_since_snapshot = 0;
            }
            let interrupted = interrupt.is_some_and(|f| f.load(Ordering::SeqCst));
            let due = (every_rows > 0 && rows_since_checkpoint >= every_rows)
                || (every_seconds > 0.0
                    && last_checkpoint.elapsed().as_secs_f64() >= every_seconds);
            if due || interrupted {
                let clock = Instant::now();
                let body = checkpoint_body(config, run_id, state, &curve, &profiles)?;
                write_checkpoint(&checkpoint_path, &body).map_err(io_err(&checkpoint_path))?;
                // What a scheduler's warning must leave time for (`[slurm] signal_lead_s`).
                notice(&format!(
                    "checkpoint at step {}: {:.1} MB written in {:.2} s",
                    state.engine.step_count(),
                    body.len() as f64 / 1e6,
                    clock.elapsed().as_secs_f64()
                ));
                rows_since_checkpoint = 0;
                last_checkpoint = Instant::now();
            }
            if interrupted {
                return Err(RunError::Interrupted {
                    checkpoint: checkpoint_path.clone(),
                });
            }
            Ok(())
        }
    });
    let stop = match stop {
        Ok(stop) => stop,
        Err(RunError::Engine(error)) if error.is_guard() => {
            return Err(keep_failed_state(
                config, out_dir, run_id, &run, &curve, &profiles, error,
            ))
        }
        Err(RunError::Engine(EngineError::DeviceLost(why))) => {
            // Nothing on the device can be read: the last checkpoint is what survives.
            let last = out_dir.join(CHECKPOINT_FILE);
            let resume = if last.exists() {
                format!(
                    "continue from the last checkpoint with `dustdem resume {}`",
                    last.display()
                )
            } else {
                "no checkpoint had been written yet".to_string()
            };
            return Err(RunError::Output(format!(
                "the GPU failed after step {}: {why}; {resume}",
                run.engine.step_count()
            )));
        }
        Err(other) => return Err(other),
    };
    write_snapshot(out_dir, snapshot_format, &run.engine.state(), "").map_err(io_err(out_dir))?;
    finish(out_dir, &run, stop, &curve_path, &profile_path)
}

/// "memory: engine arrays 151.2 MiB (1585 B per monomer), peak resident 260.3 MiB": what the
/// engine's arrays hold (where it keeps them on the host) and the process's peak.
fn memory_line<E: Engine>(engine: &E) -> Option<String> {
    const MIB: f64 = 1048576.0;
    let peak = crate::bench::memory::peak_rss_bytes()?;
    let arrays = engine.host_bytes().map_or(String::new(), |b| {
        format!(
            "engine arrays {:.1} MiB ({:.0} B per monomer), ",
            b as f64 / MIB,
            b as f64 / engine.monomer_count() as f64
        )
    });
    Some(format!(
        "memory: {arrays}peak resident {:.1} MiB",
        peak as f64 / MIB
    ))
}

fn finish<E: Engine>(
    out_dir: &Path,
    run: &Compression<E>,
    stop: StopReason,
    curve_path: &Path,
    profile_path: &Path,
) -> Result<JobSummary, RunError> {
    let (header, rows) = read_csv(curve_path).map_err(RunError::Output)?;
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (ip, iphi) = (column("p_top_pa"), column("phi"));
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r[ip], r[iphi])).collect();
    let plot_path = out_dir.join(PLOT_FILE);
    curve_plot(run.kind, &points)
        .save(&plot_path)
        .map_err(io_err(&plot_path))?;
    let last = rows
        .last()
        .map_or((f64::NAN, f64::NAN), |r| (r[iphi], r[ip]));
    let mut lines = vec![
        format!(
            "stopped at step {} (t = {:.4e} s): {stop}",
            run.engine.step_count(),
            run.engine.time()
        ),
        format!(
            "final phi {:.4}, top-wall pressure {:.4e} Pa",
            last.0, last.1
        ),
    ];
    lines.extend(memory_line(&run.engine));
    Ok(JobSummary {
        out_dir: out_dir.to_path_buf(),
        files: vec![
            out_dir.join(CONFIG_FILE),
            curve_path.to_path_buf(),
            profile_path.to_path_buf(),
            plot_path,
        ],
        lines,
    })
}
