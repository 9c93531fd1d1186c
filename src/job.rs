//! Running a configured job end to end: set up, simulate, write the curve, profiles, the
//! effective config and a plot into the output directory.

use crate::analysis::fit::Eq13;
use crate::config::{Config, ExperimentKind};
use crate::experiment::collision::{analytic_sticking_speed, head_on_collision, Outcome};
use crate::experiment::compression::{Compression, Event, Row, RunError, StopReason};
use crate::io::atomic::write_atomic;
use crate::io::csv::CsvWriter;
use crate::io::plot::{Plot, Series, Style};
use std::path::{Path, PathBuf};

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

/// What a finished job produced.
pub struct JobSummary {
    pub out_dir: PathBuf,
    pub files: Vec<PathBuf>,
    pub lines: Vec<String>,
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> RunError + '_ {
    move |e| RunError::Output(format!("{}: {e}", path.display()))
}

/// Runs `config`, writing into `out_dir`; `progress` receives a line per reported row.
pub fn run_job(
    config: &Config,
    out_dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<JobSummary, RunError> {
    std::fs::create_dir_all(out_dir).map_err(io_err(out_dir))?;
    let config_path = out_dir.join("config.toml");
    let effective = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    write_atomic(&config_path, effective.as_bytes()).map_err(io_err(&config_path))?;
    match config.experiment.kind {
        ExperimentKind::Collision => run_collision(config, out_dir, config_path),
        _ => run_compression(config, out_dir, config_path, progress),
    }
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

fn run_compression(
    config: &Config,
    out_dir: &Path,
    config_path: PathBuf,
    progress: &mut dyn FnMut(&str),
) -> Result<JobSummary, RunError> {
    let mut run = Compression::new(config)?;
    let curve_path = out_dir.join("curve.csv");
    let profile_path = out_dir.join("profiles.csv");
    let mut curve = CsvWriter::create(&curve_path, &Row::HEADER).map_err(io_err(&curve_path))?;
    let e = &config.experiment;
    curve
        .comment(&format!(
            "dustdem {} compression, {} monomers, wall speed {} m/s, dt {} ns, seed {}",
            if run.kind == ExperimentKind::Omni {
                "omnidirectional"
            } else {
                "unidirectional"
            },
            run.engine.monomers.len(),
            e.wall_speed_m_s,
            config.integration.dt_ns,
            config.sample.seed
        ))
        .map_err(io_err(&curve_path))?;
    let mut profiles = CsvWriter::create(
        &profile_path,
        &["step", "time_s", "phi_mean", "z_um", "phi"],
    )
    .map_err(io_err(&profile_path))?;
    let mut points: Vec<(f64, f64)> = Vec::new();
    let stop = run.run(&mut |event| match event {
        Event::Row(row) => {
            curve.write_row(&row.values()).map_err(|e| e.to_string())?;
            if row.p_top > 0.0 {
                points.push((row.p_top, row.phi));
            }
            progress(&format!(
                "step {:>9}  t {:.3e} s  phi {:.4}  P_top {:.4e} Pa  contacts {}",
                row.step, row.time, row.phi, row.p_top, row.contacts
            ));
            Ok(())
        }
        Event::Profile(row, slabs) => {
            for (z, phi) in slabs {
                profiles
                    .write_row(&[row.step as f64, row.time, row.phi, z * 1e4, *phi])
                    .map_err(|e| e.to_string())?;
            }
            Ok(())
        }
    })?;
    let plot_path = out_dir.join("curve.svg");
    curve_plot(run.kind, &points)
        .save(&plot_path)
        .map_err(io_err(&plot_path))?;
    let last = points.last().copied().unwrap_or((f64::NAN, f64::NAN));
    let lines = vec![
        format!(
            "stopped at step {} (t = {:.4e} s): {}",
            run.engine.step,
            run.engine.time,
            describe(stop)
        ),
        format!(
            "final phi {:.4}, top-wall pressure {:.4e} Pa",
            last.1, last.0
        ),
    ];
    Ok(JobSummary {
        out_dir: out_dir.to_path_buf(),
        files: vec![config_path, curve_path, profile_path, plot_path],
        lines,
    })
}

fn describe(stop: StopReason) -> String {
    stop.to_string()
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
