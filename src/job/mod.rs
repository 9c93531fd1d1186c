//! Running a configured job end to end: set up (or resume), simulate, write the curve,
//! profiles, checkpoints, the effective config and a plot into the output directory.

use crate::analysis::fit::Eq13;
use crate::backend::cpu::CpuEngine;
use crate::backend::gpu::context::{GpuContext, Requirements};
use crate::backend::gpu::engine::{GpuEngine, GpuError};
use crate::binary::{Decoder, Encoder};
use crate::config::{Config, ExperimentKind};
use crate::engine::{Engine, EngineError};
use crate::experiment::collision::{analytic_sticking_speed, head_on_collision, Outcome};
use crate::experiment::compression::{Compression, Event, Row, RunError, StopReason};
use crate::model::ContactLaw;
use crate::output::atomic::write_atomic;
use crate::output::checkpoint::{read_checkpoint, write_checkpoint};
use crate::output::csv::{read_csv, CsvWriter};
use crate::output::plot::{Plot, Series, Style};
use crate::output::run_dir::{
    check_resumable, new_run_id, resolve_outputs, NewRunDir, RunDir, CONFIG_FILE,
    FAILED_CHECKPOINT_FILE, OUTPUTS_BESIDE_CHECKPOINT, PLOT_FILE, SUMMARY_FILE,
};
use crate::output::snapshot::series::write_snapshot;
use crate::state::{Monomers, State, Wall};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The built-in default job: a small omnidirectional compression.
pub const DEFAULT_CONFIG: &str = include_str!("../../configs/omni_quick.toml");

/// Measured reference curves of docs/physics.md, Sect. 5.8 (Eq. 13 parameters, pressures in Pa).
pub const GUETTLER_2009_OMNI: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.58,
    p_m: 16_667.0,
    delta: 0.562,
};
pub const BLUM_SCHRAEPLER_2004_UNI: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.33,
    p_m: 5_600.0,
    delta: 0.33,
};

pub use crate::output::run_dir::{CHECKPOINT_FILE, CURVE_FILE, PROFILE_FILE};
const PROFILE_HEADER: [&str; 5] = ["step", "time_s", "phi_mean", "z_um", "phi"];

/// What a finished job produced.
pub struct JobSummary {
    pub out_dir: PathBuf,
    pub files: Vec<PathBuf>,
    pub lines: Vec<String>,
}

/// Progress of a compression, once per row.
pub struct Progress<'a> {
    pub row: &'a Row,
    /// Fraction of the way from the starting φ to φ_stop (or of max_steps, if further).
    pub fraction: f64,
    /// Steps per second of wall-clock time since the job (or resume) started.
    pub steps_per_second: f64,
}

/// Which engine runs a compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The f64 CPU reference.
    Cpu,
    /// The WGSL engine on the best adapter with f64 (an error when there is none).
    Gpu,
    /// A hardware GPU when one fits, else the CPU. A software adapter (lavapipe) is not
    /// chosen: it runs the same shaders several times slower than the CPU reference
    /// (README, benchmark); `Gpu` uses it anyway.
    Auto,
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "cpu" => Ok(Backend::Cpu),
            "gpu" => Ok(Backend::Gpu),
            "auto" => Ok(Backend::Auto),
            other => Err(format!("backend `{other}`: expected cpu, gpu or auto")),
        }
    }
}

/// The f64 CPU reference engine, built from an initial state as every engine is (the `build`
/// argument of the experiments). Collisions and calibrations run on it: it is deterministic on
/// every machine, and a GPU would not speed up two monomers or a few hundred.
pub fn reference_engine(
    law: ContactLaw,
    dt: f64,
    monomers: Monomers,
    walls: Vec<Wall>,
    pair_slots: usize,
    wall_slots: usize,
) -> Result<CpuEngine, EngineError> {
    CpuEngine::new(law, dt, monomers, walls, pair_slots, wall_slots)
}

/// How a job reports, where it runs and when it stops early.
pub struct JobOptions<'a> {
    pub progress: &'a mut dyn FnMut(&Progress),
    /// Set by a signal handler: checkpoint at the next row and stop.
    pub interrupt: Option<&'a AtomicBool>,
    pub backend: Backend,
    /// Receives one line naming the backend chosen.
    pub notice: &'a mut dyn FnMut(&str),
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> RunError + '_ {
    move |e| RunError::Output(format!("{}: {e}", path.display()))
}

/// Runs `config`, writing into `out_dir`. A directory holding the results of an earlier run
/// is refused, unless `replace`: then those results (only files dustdem writes) are removed once
/// the new run is set up. Everything that can fail in the setup (sample, walls, engine) is
/// done before the directory is touched; if writing the first files fails, they are removed.
pub fn run_job(
    config: &Config,
    out_dir: &Path,
    replace: bool,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
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

/// The GPU context a job runs on (`None`: the CPU reference), announced through the notice.
fn choose_backend(options: &mut JobOptions) -> Result<Option<GpuContext>, RunError> {
    let context = match options.backend {
        Backend::Cpu => None,
        Backend::Gpu => Some(
            GpuContext::new(&Requirements::default())
                .map_err(|e| EngineError::from(GpuError::from(e)))?,
        ),
        Backend::Auto => match GpuContext::new(&Requirements::default()) {
            Ok(ctx) if ctx.summary().device_type == wgpu::DeviceType::Cpu => {
                (options.notice)(&format!(
                    "backend: cpu (f64 reference); the only adapter, {}, is a software \
                     renderer and slower (--backend gpu uses it anyway)",
                    ctx.summary().name
                ));
                return Ok(None);
            }
            found => found.ok(),
        },
    };
    match &context {
        None => (options.notice)("backend: cpu (f64 reference)"),
        Some(ctx) => (options.notice)(&format!(
            "backend: gpu ({}, {:?} float mode)",
            ctx.summary().name,
            ctx.float_mode
        )),
    }
    Ok(context)
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

/// Continues the run a checkpoint belongs to, in the directory that holds the checkpoint:
/// once that directory's run id and the curve and profile files are checked to be the ones
/// the checkpoint recorded (before any file is changed), those files are cut back to what
/// they held at the checkpoint, then appended to. The run continues on the backend the
/// options choose; on the backend that wrote the checkpoint it continues bit for bit.
pub fn resume_job(checkpoint: &Path, options: &mut JobOptions) -> Result<JobSummary, RunError> {
    let loaded = load_checkpoint(checkpoint)?;
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

/// A checkpoint read back: the run, its config and id, and where its outputs are with the
/// length and FNV-1a hash each had when the checkpoint was written.
pub struct LoadedCheckpoint {
    pub run_id: String,
    pub config: Config,
    /// The directory holding the checkpoint (checkpoints store it relative to themselves).
    pub out_dir: PathBuf,
    pub curve_len: u64,
    pub curve_hash: u64,
    pub profile_len: u64,
    pub profile_hash: u64,
    /// The run as stored, on no engine yet.
    pub run: Compression<State>,
}

/// Reads and checks a checkpoint file completely (header, checksum, config, state).
///
/// Body (format version 2): run id, effective config, output directory relative to the
/// checkpoint's directory (each as u64 length + UTF-8), curve.csv length and hash,
/// profiles.csv length and hash (u64 each), then the run's state.
pub fn load_checkpoint(checkpoint: &Path) -> Result<LoadedCheckpoint, RunError> {
    let body = read_checkpoint(checkpoint).map_err(|e| RunError::Output(e.to_string()))?;
    let bad = |e: crate::binary::DecodeError| {
        RunError::Output(format!("checkpoint {}: {e}", checkpoint.display()))
    };
    let mut d = Decoder::new(&body);
    let run_id = String::from_utf8_lossy(d.bytes_with_len("run id").map_err(bad)?).into_owned();
    let text = String::from_utf8_lossy(d.bytes_with_len("config").map_err(bad)?).into_owned();
    let origin = format!("config inside checkpoint {}", checkpoint.display());
    let config = Config::parse(&text, &origin).map_err(|e| RunError::Output(e.to_string()))?;
    let stored = d.bytes_with_len("output directory").map_err(bad)?;
    let out_dir = resolve_outputs(checkpoint, &String::from_utf8_lossy(stored))
        .map_err(|e| RunError::Output(format!("checkpoint {}: {e}", checkpoint.display())))?;
    let curve_len = d.u64("curve length").map_err(bad)?;
    let curve_hash = d.u64("curve hash").map_err(bad)?;
    let profile_len = d.u64("profile length").map_err(bad)?;
    let profile_hash = d.u64("profile hash").map_err(bad)?;
    let run = Compression::decode_state(&config, &mut d).map_err(bad)?;
    if d.remaining() != 0 {
        return Err(RunError::Output(format!(
            "checkpoint {}: {} unexpected bytes after the state",
            checkpoint.display(),
            d.remaining()
        )));
    }
    Ok(LoadedCheckpoint {
        run_id,
        config,
        out_dir,
        curve_len,
        curve_hash,
        profile_len,
        profile_hash,
        run,
    })
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

/// The body of a checkpoint written into the run's directory (layout: [`load_checkpoint`]).
fn checkpoint_body<E: Engine>(
    config: &Config,
    run_id: &str,
    run: &Compression<E>,
    curve: &CsvWriter,
    profiles: &CsvWriter,
) -> Result<Vec<u8>, RunError> {
    let mut e = Encoder::default();
    e.bytes_with_len(run_id.as_bytes());
    let text = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    e.bytes_with_len(text.as_bytes());
    e.bytes_with_len(OUTPUTS_BESIDE_CHECKPOINT.as_bytes());
    for (length, hash) in [curve.extent(), profiles.extent()] {
        e.u64(length);
        e.u64(hash);
    }
    run.encode_state(&mut e);
    Ok(e.bytes)
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
    let mut phi_start = f64::NAN;
    let e = &config.experiment;
    let (phi_stop, max_steps) = (e.phi_stop, e.max_steps);
    let progress = &mut options.progress;
    let interrupt = options.interrupt;
    let stop = run.run(&mut |event| match event {
        Event::Row(row) => {
            curve
                .write_row(&row.values())
                .map_err(io_err(&curve_path))?;
            if phi_start.is_nan() {
                phi_start = row.phi;
            }
            let by_phi = (row.phi - phi_start) / (phi_stop - phi_start);
            let by_steps = row.step as f64 / max_steps as f64;
            let elapsed = started.elapsed().as_secs_f64().max(1e-9);
            progress(&Progress {
                row,
                fraction: by_phi.max(by_steps).clamp(0.0, 1.0),
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
                let body = checkpoint_body(config, run_id, state, &curve, &profiles)?;
                write_checkpoint(&checkpoint_path, &body).map_err(io_err(&checkpoint_path))?;
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

/// After a run-time guard fired: a checkpoint and a snapshot of the failed state for
/// inspection (beside, not over, the last good checkpoint), and a message naming them.
fn keep_failed_state<E: Engine>(
    config: &Config,
    out_dir: &Path,
    run_id: &str,
    run: &Compression<E>,
    curve: &CsvWriter,
    profiles: &CsvWriter,
    error: EngineError,
) -> RunError {
    let mut kept = Vec::new();
    let checkpoint = out_dir.join(FAILED_CHECKPOINT_FILE);
    let body = checkpoint_body(config, run_id, run, curve, profiles);
    if let Ok(body) = body {
        if write_checkpoint(&checkpoint, &body).is_ok() {
            kept.push(checkpoint);
        }
    }
    let choice = match config.output.snapshot_format {
        crate::config::SnapshotChoice::None => crate::config::SnapshotChoice::Vtu,
        c => c,
    };
    let snapshot = write_snapshot(out_dir, choice, &run.engine.state(), "_failed");
    if let Ok(files) = &snapshot {
        kept.extend(files.iter().cloned());
    }
    let last_good = out_dir.join(CHECKPOINT_FILE);
    let mut message = format!("{error}; the failed state is kept in:");
    for f in &kept {
        message.push_str(&format!(" {}", f.display()));
    }
    if let Err(e) = snapshot {
        message.push_str(&format!(" (no snapshot: {e})"));
    }
    if last_good.exists() {
        message.push_str(&format!("; last good checkpoint: {}", last_good.display()));
    }
    RunError::Output(message)
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
    let points: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r[ip] > 0.0)
        .map(|r| (r[ip], r[iphi]))
        .collect();
    let plot_path = out_dir.join(PLOT_FILE);
    curve_plot(run.kind, &points)
        .save(&plot_path)
        .map_err(io_err(&plot_path))?;
    let last = rows
        .last()
        .map_or((f64::NAN, f64::NAN), |r| (r[iphi], r[ip]));
    let lines = vec![
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

fn run_collision(
    config: &Config,
    fresh: NewRunDir,
    effective: &str,
) -> Result<JobSummary, RunError> {
    let law = config.contact_law();
    let speed = config.experiment.collision_speed_m_s * 100.0;
    let result = head_on_collision(&law, speed, config.dt(), 5.0, reference_engine)?;
    let outcome = match result.outcome {
        Outcome::Stuck => "stuck".to_string(),
        Outcome::Separated { rebound_speed } => {
            format!("separated, rebound speed {:.4} m/s", rebound_speed / 100.0)
        }
    };
    let lines = vec![
        format!("head-on collision at {:.4} m/s: {outcome}", speed / 100.0),
        format!(
            "largest overlap {:.4} delta0",
            result.max_overlap / law.pair.delta0
        ),
        format!(
            "undamped sticking threshold from the JKR loop: {:.4} m/s",
            analytic_sticking_speed(&law) / 100.0
        ),
    ];
    let (dir, summary_path) = create_run_dir(fresh, effective, |dir| {
        let summary_path = dir.dir.join(SUMMARY_FILE);
        write_atomic(&summary_path, (lines.join("\n") + "\n").as_bytes())
            .map_err(io_err(&summary_path))?;
        Ok(summary_path)
    })?;
    Ok(JobSummary {
        files: vec![dir.dir.join(CONFIG_FILE), summary_path],
        out_dir: dir.dir,
        lines,
    })
}

/// φ against P with the measured reference curve of the same geometry.
pub fn curve_plot(kind: ExperimentKind, points: &[(f64, f64)]) -> Plot {
    let (name, reference) = match kind {
        ExperimentKind::Uni => ("Blum & Schräpler 2004 (Eq. 13)", BLUM_SCHRAEPLER_2004_UNI),
        _ => ("Güttler et al. 2009 (Eq. 13)", GUETTLER_2009_OMNI),
    };
    let measured: Vec<(f64, f64)> = (0..=80)
        .map(|k| {
            let p = 10f64.powf(1.0 + 6.0 * k as f64 / 80.0);
            (p, reference.phi(p))
        })
        .collect();
    let mut plot = Plot::new(
        "Compressive strength",
        "pressure P [Pa]",
        "filling factor φ",
    );
    plot.x_log = true;
    plot.x_range = Some((10.0, 1e7));
    plot.y_range = Some((0.0, 0.75));
    plot.series.push(Series::new(
        "simulation (top wall)",
        points.to_vec(),
        Style::Line,
    ));
    plot.series.push(Series::new(name, measured, Style::Dashed));
    plot
}
