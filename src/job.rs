//! Running a configured job end to end: set up (or resume), simulate, write the curve,
//! profiles, checkpoints, the effective config and a plot into the output directory.

use crate::analysis::fit::Eq13;
use crate::config::{Config, ExperimentKind};
use crate::experiment::collision::{analytic_sticking_speed, head_on_collision, Outcome};
use crate::experiment::compression::{Compression, Engine, Event, Row, RunError, StopReason};
use crate::gpu::context::{GpuContext, Requirements};
use crate::gpu::engine::{GpuEngine, GpuError};
use crate::io::atomic::write_atomic;
use crate::io::binary::{Decoder, Encoder};
use crate::io::checkpoint::{read_checkpoint, write_checkpoint};
use crate::io::csv::{read_csv, CsvWriter};
use crate::io::plot::{Plot, Series, Style};
use crate::snapshots::{write_failed_snapshot, write_snapshot};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The built-in default job: a small omnidirectional compression.
pub const DEFAULT_CONFIG: &str = include_str!("../configs/omni_quick.toml");

/// Measured reference curves of physics.md (Eq. 13 parameters, pressures in Pa).
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

pub const CURVE_FILE: &str = "curve.csv";
pub const PROFILE_FILE: &str = "profiles.csv";
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
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

/// Runs `config`, writing into `out_dir`.
pub fn run_job(
    config: &Config,
    out_dir: &Path,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    std::fs::create_dir_all(out_dir).map_err(io_err(out_dir))?;
    let config_path = out_dir.join("config.toml");
    let effective = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    write_atomic(&config_path, effective.as_bytes()).map_err(io_err(&config_path))?;
    match config.experiment.kind {
        ExperimentKind::Collision => run_collision(config, out_dir, config_path),
        _ => match choose_backend(options)? {
            None => start(config, out_dir, Compression::new(config)?, options),
            Some(ctx) => {
                let run = Compression::with_engine(config, |law, dt, m, walls, ps, ws| {
                    Ok(GpuEngine::new(ctx, law, dt, m, walls, ps, ws)?)
                })?;
                start(config, out_dir, run, options)
            }
        },
    }
}

/// The GPU context a job runs on (`None`: the CPU reference), announced through the notice.
fn choose_backend(options: &mut JobOptions) -> Result<Option<GpuContext>, RunError> {
    let context = match options.backend {
        Backend::Cpu => None,
        Backend::Gpu => Some(GpuContext::new(&Requirements::default()).map_err(GpuError::from)?),
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

/// Creates the output tables and the first snapshot of a fresh compression, then runs it.
fn start<E: Engine>(
    config: &Config,
    out_dir: &Path,
    run: Compression<E>,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    let curve_path = out_dir.join(CURVE_FILE);
    let mut curve = CsvWriter::create(&curve_path, &Row::HEADER).map_err(io_err(&curve_path))?;
    curve
        .comment(&describe_run(config, &run))
        .map_err(io_err(&curve_path))?;
    let profile_path = out_dir.join(PROFILE_FILE);
    let profiles =
        CsvWriter::create(&profile_path, &PROFILE_HEADER).map_err(io_err(&profile_path))?;
    write_snapshot(
        out_dir,
        config.output.snapshot_format,
        &run.engine.state(),
        "",
    )
    .map_err(io_err(out_dir))?;
    drive(config, out_dir, run, curve, profiles, options)
}

/// Continues the run a checkpoint belongs to, in the output directory it names: the curve and
/// profile files are cut back to what they held at the checkpoint, then appended to. The run
/// continues on the backend the options choose; on the backend that wrote the checkpoint it
/// continues bit for bit.
pub fn resume_job(checkpoint: &Path, options: &mut JobOptions) -> Result<JobSummary, RunError> {
    let loaded = load_checkpoint(checkpoint)?;
    match choose_backend(options)? {
        None => continue_job(loaded, loaded_run_cpu, options),
        Some(ctx) => continue_job(
            loaded,
            |run| run.map_engine(|cpu| Ok(GpuEngine::resume(ctx, &cpu)?)),
            options,
        ),
    }
}

fn loaded_run_cpu(run: Compression) -> Result<Compression, RunError> {
    Ok(run)
}

/// Reopens a checkpoint's outputs and drives its run on the engine `engine` makes of it.
fn continue_job<E: Engine>(
    loaded: LoadedCheckpoint,
    engine: impl FnOnce(Compression) -> Result<Compression<E>, RunError>,
    options: &mut JobOptions,
) -> Result<JobSummary, RunError> {
    let run = engine(loaded.run)?;
    let out_dir = loaded.out_dir;
    let curve_path = out_dir.join(CURVE_FILE);
    let curve = CsvWriter::reopen(&curve_path, Row::HEADER.len(), loaded.curve_len)
        .map_err(io_err(&curve_path))?;
    let profile_path = out_dir.join(PROFILE_FILE);
    let profiles = CsvWriter::reopen(&profile_path, PROFILE_HEADER.len(), loaded.profile_len)
        .map_err(io_err(&profile_path))?;
    drive(&loaded.config, &out_dir, run, curve, profiles, options)
}

/// A checkpoint read back: the run, its config, and where its outputs are.
pub struct LoadedCheckpoint {
    pub config: Config,
    pub out_dir: PathBuf,
    pub curve_len: u64,
    pub profile_len: u64,
    pub run: Compression,
}

/// Reads and checks a checkpoint file completely (header, checksum, config, state).
pub fn load_checkpoint(checkpoint: &Path) -> Result<LoadedCheckpoint, RunError> {
    let body = read_checkpoint(checkpoint).map_err(|e| RunError::Output(e.to_string()))?;
    let bad = |e: crate::io::binary::DecodeError| {
        RunError::Output(format!("checkpoint {}: {e}", checkpoint.display()))
    };
    let mut d = Decoder::new(&body);
    let text = String::from_utf8_lossy(d.bytes_with_len("config").map_err(bad)?).into_owned();
    let origin = format!("config inside checkpoint {}", checkpoint.display());
    let config = Config::parse(&text, &origin).map_err(|e| RunError::Output(e.to_string()))?;
    let out_dir = PathBuf::from(
        String::from_utf8_lossy(d.bytes_with_len("output directory").map_err(bad)?).into_owned(),
    );
    let curve_len = d.u64("curve length").map_err(bad)?;
    let profile_len = d.u64("profile length").map_err(bad)?;
    let run = Compression::decode_state(&config, &mut d).map_err(bad)?;
    if d.remaining() != 0 {
        return Err(RunError::Output(format!(
            "checkpoint {}: {} unexpected bytes after the state",
            checkpoint.display(),
            d.remaining()
        )));
    }
    Ok(LoadedCheckpoint {
        config,
        out_dir,
        curve_len,
        profile_len,
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

fn checkpoint_body<E: Engine>(
    config: &Config,
    out_dir: &Path,
    run: &Compression<E>,
    curve: &Path,
    profiles: &Path,
) -> Result<Vec<u8>, RunError> {
    let mut e = Encoder::default();
    let text = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    e.bytes_with_len(text.as_bytes());
    let absolute = std::path::absolute(out_dir).map_err(io_err(out_dir))?;
    e.bytes_with_len(absolute.to_string_lossy().as_bytes());
    e.u64(std::fs::metadata(curve).map_err(io_err(curve))?.len());
    e.u64(std::fs::metadata(profiles).map_err(io_err(profiles))?.len());
    run.encode_state(&mut e);
    Ok(e.bytes)
}

/// The compression loop shared by fresh and resumed runs.
fn drive<E: Engine>(
    config: &Config,
    out_dir: &Path,
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
                let body = checkpoint_body(config, out_dir, state, &curve_path, &profile_path)?;
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
        Err(RunError::Engine(error)) => {
            return Err(keep_failed_state(config, out_dir, &run, error))
        }
        Err(RunError::Gpu(GpuError::DeviceLost(why))) => {
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
    run: &Compression<E>,
    error: crate::cpu::EngineError,
) -> RunError {
    let mut kept = Vec::new();
    let checkpoint = out_dir.join("checkpoint-failed.bin");
    let body = checkpoint_body(
        config,
        out_dir,
        run,
        &out_dir.join(CURVE_FILE),
        &out_dir.join(PROFILE_FILE),
    );
    if let Ok(body) = body {
        if write_checkpoint(&checkpoint, &body).is_ok() {
            kept.push(checkpoint);
        }
    }
    // A VTU whatever the run's snapshot format: it keeps NaN and inf as they are.
    let snapshot = write_failed_snapshot(out_dir, &run.engine.state());
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
    let plot_path = out_dir.join("curve.svg");
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
            out_dir.join("config.toml"),
            curve_path.to_path_buf(),
            profile_path.to_path_buf(),
            plot_path,
        ],
        lines,
    })
}

fn run_collision(
    config: &Config,
    out_dir: &Path,
    config_path: PathBuf,
) -> Result<JobSummary, RunError> {
    let law = config.contact_law();
    let speed = config.experiment.collision_speed_m_s * 100.0;
    let result = head_on_collision(&law, speed, config.dt(), 5.0)?;
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
    let summary_path = out_dir.join("summary.txt");
    write_atomic(&summary_path, (lines.join("\n") + "\n").as_bytes())
        .map_err(io_err(&summary_path))?;
    Ok(JobSummary {
        out_dir: out_dir.to_path_buf(),
        files: vec![config_path, summary_path],
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
