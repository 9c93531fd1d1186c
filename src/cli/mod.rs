//! The dustdem command line: parses arguments and calls the library.

use crate::analysis::fit::{fit_eq13, FitOptions};
use crate::backend::gpu::buffers::Sizes;
use crate::backend::gpu::context::{GpuContext, Requirements};
use crate::calibrate::measured::Geometry;
use crate::calibrate::synth::{write_synth, SynthSpec};
use crate::calibrate::{parse_effect, run_calibration, Settings};
use crate::config::{stable_time_step, Config, ExperimentKind};
use crate::experiment::collision::analytic_sticking_speed;
use crate::experiment::setup::build_sample;
use crate::job::{resume_job, run_job, Backend, JobOptions, JobSummary, Progress, DEFAULT_CONFIG};
use crate::material::{
    chokshi_sticking_velocity, normal_period, rolling_energy_quarter_turn, sliding_period, Derived,
};
use crate::output::csv::read_csv;
use crate::sample::{interior_filling_factor, Footprint};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "dustdem",
    version,
    about = "Molecular dynamics of porous dust agglomerates"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run an experiment; without a config, the built-in omni_quick job.
    Run {
        config: Option<PathBuf>,
        /// Output directory (overrides [output] dir).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Engine: cpu (f64 reference), gpu (WGSL on an adapter with f64) or auto (a hardware
        /// GPU when one fits, else cpu; software adapters such as lavapipe only with gpu).
        #[arg(long, default_value = "auto")]
        backend: Backend,
        /// Replace the results of an earlier run in the output directory: once the new run is
        /// set up, its checkpoints, snapshots and result files (only files dustdem writes) are
        /// removed. Without it such a directory is refused.
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        report: ReportArgs,
    },
    /// Continue a run from its checkpoint, appending to its outputs.
    Resume {
        checkpoint: PathBuf,
        /// Engine to continue on: cpu, gpu or auto (as for `run`). Continuing on the backend
        /// that wrote the checkpoint gives the same bits as an uninterrupted run.
        #[arg(long, default_value = "auto")]
        backend: Backend,
        #[command(flatten)]
        report: ReportArgs,
    },
    /// Generate the sample a config describes and write it to a sample file.
    Generate {
        config: Option<PathBuf>,
        #[arg(long, default_value = "sample.txt")]
        out: PathBuf,
    },
    /// Fit Eq. 13 to a curve CSV (columns p_top_pa and phi).
    Fit {
        curve: PathBuf,
        /// Fix φ₁ instead of fitting it.
        #[arg(long)]
        phi1: Option<f64>,
        /// Fix φ₂ instead of fitting it.
        #[arg(long)]
        phi2: Option<f64>,
        /// Use only points with P ≥ this [Pa].
        #[arg(long, default_value_t = 0.0)]
        p_min: f64,
    },
    /// Print the material, derived and model constants of a config, and the GPU adapter.
    Info {
        config: Option<PathBuf>,
        /// N for the GPU memory estimate (default: the config's sample size).
        #[arg(long)]
        monomers: Option<usize>,
    },
    /// Compare a config with measured data and name the effect that explains the gap; writes
    /// report.md, calibration.png and corrected.toml.
    Calibrate {
        /// Measured-data file (see configs/measured/); repeat it to fit the curves of several
        /// files jointly.
        #[arg(long, required = true)]
        measured: Vec<PathBuf>,
        /// Base config: material, model, sample size, wall speed, time step.
        #[arg(long)]
        config: PathBuf,
        #[arg(long, default_value = "runs/calibration")]
        out: PathBuf,
        /// RBD sample seeds; each compression curve is simulated once per seed.
        #[arg(long, value_delimiter = ',', default_value = "1,2,3")]
        seeds: Vec<u64>,
        /// Effects added one after the other at most.
        #[arg(long, default_value_t = 2)]
        rounds: usize,
        /// Simulation threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Write measured-like data from the simulator, with effects switched on and noise added.
    Synth {
        /// Base config (sample size, wall speed, time step, model).
        #[arg(long)]
        config: PathBuf,
        /// An effect and its factor, e.g. rolling_stiffness=8 (repeatable).
        #[arg(long)]
        effect: Vec<String>,
        /// Compression curves to write: omni, uni or both.
        #[arg(long, value_delimiter = ',', default_value = "omni")]
        geometry: Vec<Geometry>,
        /// Leave out the sticking velocity.
        #[arg(long)]
        no_sticking: bool,
        /// RBD sample seeds averaged per curve.
        #[arg(long, value_delimiter = ',', default_value = "101,102,103")]
        seeds: Vec<u64>,
        #[arg(long, default_value_t = 1e2)]
        p_min: f64,
        #[arg(long, default_value_t = 1e5)]
        p_max: f64,
        /// Points per curve.
        #[arg(long, default_value_t = 10)]
        points: usize,
        /// 1-sigma noise added to each filling factor.
        #[arg(long, default_value_t = 0.005)]
        noise: f64,
        /// Relative 1-sigma noise of the sticking velocity.
        #[arg(long, default_value_t = 0.05)]
        sticking_noise: f64,
        #[arg(long, default_value_t = 1)]
        noise_seed: u64,
        #[arg(long)]
        out: PathBuf,
        #[arg(long)]
        threads: Option<usize>,
    },
}

#[derive(clap::Args)]
struct ReportArgs {
    /// Print only the summary.
    #[arg(long)]
    quiet: bool,
    /// One `key=value` line per row on stderr instead of a progress bar (for scripts and
    /// cluster logs).
    #[arg(long)]
    log_lines: bool,
}

/// Shows progress as a bar (on a terminal), as machine-readable lines, or not at all.
struct Reporter {
    bar: Option<ProgressBar>,
    log_lines: bool,
}

impl Reporter {
    fn new(args: &ReportArgs) -> Self {
        let bar = (!args.quiet && !args.log_lines).then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {percent:>3}% eta {eta} | {msg}")
                    .expect("valid template"),
            );
            bar
        });
        Reporter {
            bar,
            log_lines: args.log_lines && !args.quiet,
        }
    }

    fn report(&self, p: &Progress) {
        let r = p.row;
        if let Some(bar) = &self.bar {
            bar.set_position((p.fraction * 1000.0) as u64);
            bar.set_message(format!(
                "step {} | {:.3e} steps/s | phi {:.4} | P {:.3e} Pa",
                r.step, p.steps_per_second, r.phi, r.p_top
            ));
        }
        if self.log_lines {
            eprintln!(
                "row step={} time_s={:e} phi={} p_top_pa={:e} p_bottom_pa={:e} contacts={} steps_per_s={:.4e} progress={:.4}",
                r.step, r.time, r.phi, r.p_top, r.p_bottom, r.contacts, p.steps_per_second, p.fraction
            );
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// SIGINT and SIGTERM raise this flag; the run checkpoints at the next row and stops.
fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // If a handler cannot be installed the run simply cannot be interrupted cleanly.
        let _ = signal_hook::flag::register(signal, Arc::clone(&flag));
    }
    flag
}

fn print_summary(summary: &JobSummary) {
    for line in &summary.lines {
        println!("{line}");
    }
    println!("results in {}:", summary.out_dir.display());
    for f in &summary.files {
        println!("  {}", f.display());
    }
}

fn load_config(path: Option<&Path>) -> Result<Config, String> {
    match path {
        Some(p) => Config::load(p).map_err(|e| e.to_string()),
        None => Config::parse(DEFAULT_CONFIG, "built-in omni_quick").map_err(|e| e.to_string()),
    }
}

fn run(
    config: Option<PathBuf>,
    out: Option<PathBuf>,
    backend: Backend,
    force: bool,
    args: ReportArgs,
) -> Result<(), String> {
    let config = load_config(config.as_deref())?;
    let out_dir = out.unwrap_or_else(|| config.output.dir.clone());
    let reporter = Reporter::new(&args);
    let flag = interrupt_flag();
    let mut progress = |p: &Progress| reporter.report(p);
    let quiet = args.quiet;
    let mut notice = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let mut options = JobOptions {
        progress: &mut progress,
        interrupt: Some(&flag),
        backend,
        notice: &mut notice,
    };
    let result = run_job(&config, &out_dir, force, &mut options);
    reporter.finish();
    print_summary(&result.map_err(|e| e.to_string())?);
    Ok(())
}

fn resume(checkpoint: PathBuf, backend: Backend, args: ReportArgs) -> Result<(), String> {
    let reporter = Reporter::new(&args);
    let flag = interrupt_flag();
    let mut progress = |p: &Progress| reporter.report(p);
    let quiet = args.quiet;
    let mut notice = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let mut options = JobOptions {
        progress: &mut progress,
        interrupt: Some(&flag),
        backend,
        notice: &mut notice,
    };
    let result = resume_job(&checkpoint, &mut options);
    reporter.finish();
    print_summary(&result.map_err(|e| e.to_string())?);
    Ok(())
}

fn generate(config: Option<PathBuf>, out: PathBuf) -> Result<(), String> {
    let config = load_config(config.as_deref())?;
    let law = config.contact_law();
    let sample = build_sample(&config, &law).map_err(|e| e.to_string())?;
    sample.save(&out).map_err(|e| e.to_string())?;
    let size = match sample.footprint {
        Footprint::Box { side } => format!("box side {:.3} µm", side * 1e4),
        Footprint::Cylinder { radius } => format!("cylinder radius {:.3} µm", radius * 1e4),
    };
    println!(
        "{} monomers, {size}, height {:.3} µm, interior filling factor {:.4}, bulk {:.4}",
        sample.positions.len(),
        (sample.z_max() + sample.radius) * 1e4,
        interior_filling_factor(&sample),
        sample.filling_factor_bulk()
    );
    println!("wrote {}", out.display());
    Ok(())
}

fn fit(curve: PathBuf, phi1: Option<f64>, phi2: Option<f64>, p_min: f64) -> Result<(), String> {
    let (header, rows) = read_csv(&curve)?;
    let column = |name: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| {
            format!(
                "{}: no column '{name}' (have: {})",
                curve.display(),
                header.join(", ")
            )
        })
    };
    let (ip, iphi) = (column("p_top_pa")?, column("phi")?);
    let (mut p, mut phi) = (Vec::new(), Vec::new());
    for row in &rows {
        if row[ip].is_finite() && row[ip] > 0.0 && row[ip] >= p_min {
            p.push(row[ip]);
            phi.push(row[iphi]);
        }
    }
    let options = FitOptions {
        fix_phi1: phi1,
        fix_phi2: phi2,
        ..FitOptions::default()
    };
    let r = fit_eq13(&p, &phi, None, &options).map_err(|e| format!("{}: {e}", curve.display()))?;
    println!("Eq. 13 fit to {} points of {}:", p.len(), curve.display());
    let show = |fixed: bool, value: f64, err: f64| {
        if fixed {
            format!("{value:.5} (fixed)")
        } else {
            format!("{value:.5} ± {err:.5}")
        }
    };
    println!(
        "  phi1  = {}",
        show(phi1.is_some(), r.params.phi1, r.std_err.phi1)
    );
    println!(
        "  phi2  = {}",
        show(phi2.is_some(), r.params.phi2, r.std_err.phi2)
    );
    println!("  p_m   = {:.5e} ± {:.2e} Pa", r.params.p_m, r.std_err.p_m);
    println!("  Delta = {:.5} ± {:.5}", r.params.delta, r.std_err.delta);
    println!(
        "  rms residual {:.3e}, converged {}",
        (r.rss / p.len() as f64).sqrt(),
        r.converged
    );
    Ok(())
}

fn info(config: Option<PathBuf>, monomers: Option<usize>) -> Result<(), String> {
    let config = load_config(config.as_deref())?;
    let m = config.material();
    let law = config.contact_law();
    let d = Derived::new(&m, config.twisting_stiffness());
    println!("material: r = {:.4e} cm, rho = {} g/cm3, gamma = {} erg/cm2, E = {:.4e} dyn/cm2, nu = {}, xi_crit = {:.3e} cm",
        m.radius, m.density, m.surface_energy, m.youngs_modulus, m.poisson, m.xi_crit);
    println!(
        "mass {:.6e} g, moment of inertia {:.6e} g cm2",
        d.mass, d.moment_of_inertia
    );
    println!(
        "E* {:.6e}, G {:.6e}, G* {:.6e} dyn/cm2",
        d.e_star, d.shear_modulus, d.g_star
    );
    for (name, c) in [
        ("monomer-monomer", law.pair),
        ("monomer-wall (factors 1)", law.wall),
    ] {
        println!("{name}: R {:.6e} cm, a0 {:.6e} cm, delta0 {:.6e} cm, F_c {:.6e} dyn, delta_c {:.6e} cm",
            c.reduced_radius, c.a0, c.delta0, c.f_c, c.delta_c);
        println!("  k_r {:.6e} dyn/cm, k_s {:.6e} dyn/cm, k_t {:.6e} erg (modifiers applied); xi_crit {:.4e} cm, zeta_crit {:.6e} cm, phi_crit {:.6e} rad",
            c.k_r, c.k_s, c.k_t, c.xi_crit, c.zeta_crit, c.phi_crit);
    }
    println!(
        "model: m_r = {}, m_s = {}, m_t = {}, k_t form {:?}, damping {:?}",
        config.model.rolling_modifier,
        config.model.sliding_modifier,
        config.model.twisting_modifier,
        config.model.twisting_stiffness,
        config.model.damping
    );
    println!(
        "sticking: JKR loop {:.4} cm/s, Chokshi {:.4} cm/s",
        analytic_sticking_speed(&law),
        chokshi_sticking_velocity(&m, &d)
    );
    println!(
        "E_roll (6 pi^2 gamma R xi_crit) {:.6e} erg",
        rolling_energy_quarter_turn(&m, &d)
    );
    println!(
        "periods: normal {:.4} ns, sliding {:.4} ns (m_s = {})",
        normal_period(&d) * 1e9,
        sliding_period(&d, config.model.sliding_modifier) * 1e9,
        config.model.sliding_modifier
    );
    println!(
        "time step {} ns, stability limit {:.4} ns",
        config.integration.dt_ns,
        stable_time_step(&law, &config.wall_factors()) * 1e9
    );
    gpu_info(&config, monomers.unwrap_or(config.sample.monomers));
    Ok(())
}

/// The adapter the GPU backend would use, and whether N monomers fit on it.
fn gpu_info(config: &Config, n: usize) {
    let walls = if config.experiment.kind == ExperimentKind::Omni {
        6
    } else {
        2
    };
    let sizes = Sizes::new(
        n,
        walls,
        config.integration.pair_slots,
        config.integration.wall_slots,
    );
    let (name, largest) = sizes.largest_binding();
    let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
    println!(
        "gpu memory for N = {n}: {:.1} MiB ({:.0} B per monomer), largest binding `{name}` \
         {:.1} MiB",
        mib(sizes.total_bytes()),
        sizes.bytes_per_monomer(),
        mib(largest)
    );
    match GpuContext::new(&Requirements::default()) {
        Ok(ctx) => {
            println!("gpu: {}", ctx.summary());
            if ctx.summary().device_type == wgpu::DeviceType::Cpu {
                println!(
                    "gpu: software adapter: `--backend auto` runs on the cpu, `--backend gpu` here"
                );
            }
            match sizes.check(&ctx.device.limits()) {
                Ok(()) => println!("gpu: N = {n} fits"),
                Err(e) => println!("gpu: N = {n} does not fit: {e}"),
            }
        }
        Err(e) => println!("gpu: none usable ({e}); runs use the cpu backend"),
    }
}

fn calibrate(
    measured: &[PathBuf],
    config: &Path,
    out: &Path,
    seeds: Vec<u64>,
    rounds: usize,
    threads: Option<usize>,
) -> Result<(), String> {
    let mut settings = Settings {
        seeds,
        max_rounds: rounds,
        ..Settings::default()
    };
    if let Some(t) = threads {
        settings.threads = t;
    }
    let progress = |line: &str| eprintln!("{line}");
    let (lines, files) = run_calibration(measured, config, out, &settings, &progress)?;
    for line in lines {
        println!("{line}");
    }
    println!("results in {}:", out.display());
    for f in files {
        println!("  {}", f.display());
    }
    Ok(())
}

fn synth(
    config: &Path,
    effects: &[String],
    spec: &SynthSpec,
    threads: Option<usize>,
    out: &Path,
) -> Result<(), String> {
    let config = Config::load(config).map_err(|e| e.to_string())?;
    let effects = effects
        .iter()
        .map(|e| parse_effect(e).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let threads = threads.unwrap_or_else(|| Settings::default().threads);
    let progress = |line: &str| eprintln!("{line}");
    let set = write_synth(&config, &effects, spec, threads, out, &progress)?;
    println!(
        "wrote {} ({} compression curve(s), {} sticking velocity)",
        out.display(),
        set.compression.len(),
        set.sticking.len()
    );
    Ok(())
}

/// Parses the command line and runs the command; errors are printed, exit status 2.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            config,
            out,
            backend,
            force,
            report,
        } => run(config, out, backend, force, report),
        Command::Resume {
            checkpoint,
            backend,
            report,
        } => resume(checkpoint, backend, report),
        Command::Generate { config, out } => generate(config, out),
        Command::Fit {
            curve,
            phi1,
            phi2,
            p_min,
        } => fit(curve, phi1, phi2, p_min),
        Command::Info { config, monomers } => info(config, monomers),
        Command::Calibrate {
            measured,
            config,
            out,
            seeds,
            rounds,
            threads,
        } => calibrate(&measured, &config, &out, seeds, rounds, threads),
        Command::Synth {
            config,
            effect,
            geometry,
            no_sticking,
            seeds,
            p_min,
            p_max,
            points,
            noise,
            sticking_noise,
            noise_seed,
            out,
            threads,
        } => {
            let spec = SynthSpec {
                geometries: geometry,
                sticking: !no_sticking,
                seeds,
                pressure_range: (p_min, p_max),
                points,
                phi_noise: noise,
                sticking_noise,
                noise_seed,
            };
            synth(&config, &effect, &spec, threads, &out)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
