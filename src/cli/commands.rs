//! What each subcommand does: load the config, call the library, print what it returns.

use super::args::{BenchArgs, ReportArgs};
use super::progress::{
    interrupt_flag, mark_stopped_at_checkpoint, print_summary, release_locks_on_signal, Reporter,
};
use crate::analysis::fit::{fit_eq13, FitOptions};
use crate::bench::{run_bench, write_tables, Options as BenchOptions};
use crate::config::{stable_time_step, Config};
use crate::experiment::collision::analytic_sticking_speed;
use crate::experiment::compression::RunError;
use crate::experiment::setup::build_sample;
use crate::job::{
    gpu_report, resume_job, run_job, Backend, JobOptions, JobSummary, Progress, DEFAULT_CONFIG,
};
use crate::material::{
    chokshi_sticking_velocity, normal_period, rolling_energy_quarter_turn, sliding_period, Derived,
};
use crate::output::csv::read_csv;
use crate::output::lock::lock_dir;
use crate::sample::{interior_filling_factor, Footprint};
use std::path::{Path, PathBuf};

fn load_config(path: Option<&Path>) -> Result<Config, String> {
    match path {
        Some(p) => Config::load(p).map_err(|e| e.to_string()),
        None => Config::parse(DEFAULT_CONFIG, "built-in omni_quick").map_err(|e| e.to_string()),
    }
}

pub(super) fn run(
    config: Option<PathBuf>,
    out: Option<PathBuf>,
    backend: Backend,
    force: bool,
    args: ReportArgs,
) -> Result<(), String> {
    use_threads(args.threads)?;
    let config = load_config(config.as_deref())?;
    let out_dir = out.unwrap_or_else(|| config.output.dir.clone());
    drive(backend, &args, |options| {
        run_job(&config, &out_dir, force, options)
    })
}

pub(super) fn resume(
    checkpoint: PathBuf,
    backend: Backend,
    args: ReportArgs,
) -> Result<(), String> {
    use_threads(args.threads)?;
    drive(backend, &args, |options| resume_job(&checkpoint, options))
}

/// Sizes the pool the CPU engine runs in (rayon's global pool) from `--threads`.
fn use_threads(threads: Option<usize>) -> Result<(), String> {
    let Some(t) = threads else {
        return Ok(());
    };
    if !(1..=1024).contains(&t) {
        return Err(format!("--threads {t}: out of range; allowed 1 to 1024"));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(t)
        .build_global()
        .map_err(|e| format!("--threads {t}: {e}"))
}

/// Runs a job with the progress reporting, interrupt flag and notices of the command line,
/// then prints its summary (shared by `run` and `resume`).
fn drive(
    backend: Backend,
    args: &ReportArgs,
    job: impl FnOnce(&mut JobOptions) -> Result<JobSummary, RunError>,
) -> Result<(), String> {
    let reporter = Reporter::new(args);
    let flag = interrupt_flag();
    let mut progress = |p: &Progress| reporter.report(p);
    let quiet = args.quiet;
    let mut notice = |line: &str| {
        if !quiet {
            reporter.note(line);
        }
    };
    let mut options = JobOptions {
        progress: &mut progress,
        interrupt: Some(&flag),
        backend,
        precision: args.precision,
        notice: &mut notice,
    };
    let result = job(&mut options);
    reporter.finish();
    if matches!(result, Err(RunError::Interrupted { .. })) {
        mark_stopped_at_checkpoint();
    }
    print_summary(&result.map_err(|e| e.to_string())?);
    Ok(())
}

pub(super) fn generate(config: Option<PathBuf>, out: PathBuf) -> Result<(), String> {
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

pub(super) fn fit(
    curve: PathBuf,
    phi1: Option<f64>,
    phi2: Option<f64>,
    p_min: f64,
) -> Result<(), String> {
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

pub(super) fn info(config: Option<PathBuf>, monomers: Option<usize>) -> Result<(), String> {
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
    for line in gpu_report(&config, monomers.unwrap_or(config.sample.monomers)) {
        println!("{line}");
    }
    Ok(())
}

/// `dustdem bench`: the options checked, then the measurement and its tables.
pub(super) fn bench_command(a: BenchArgs) -> Result<(), String> {
    let o = BenchOptions::parse(
        &a.sizes,
        a.seconds,
        a.rounds,
        &a.threads,
        &a.backends,
        a.lammps,
        a.out,
    )?
    .with_samples(&a.samples, a.prepare_speed)?;
    let options = BenchOptions {
        sample_order: a.sample_order,
        untallied: a.untallied,
        // This executable runs the whole runs of `--lammps`.
        dustdem_exe: std::env::current_exe().ok(),
        ..o
    };
    let progress = |line: &str| eprintln!("{line}");
    let report = run_bench(&options, &progress)?;
    for path in write_tables(&report)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// `v` if it lies in `lo..=hi`; otherwise an error naming the flag, value and range.
pub(super) fn in_range(flag: &str, v: usize, lo: usize, hi: usize) -> Result<usize, String> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{flag} {v}: out of range; allowed {lo} to {hi}"))
    }
}

/// `dustdem reproduce`: runs (or submits, or reports) a tier of the paper's results.
pub(super) fn reproduce(
    tier: crate::reproduce::Tier,
    out: PathBuf,
    runs: Option<PathBuf>,
    jobs: Option<usize>,
    slurm: bool,
    report_only: bool,
) -> Result<(), String> {
    let _lock = lock_dir(&out)?;
    // The sweeps it starts stop on their own signals; it only needs to leave no lock behind.
    release_locks_on_signal();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let request = crate::reproduce::Request {
        tier,
        out,
        runs,
        jobs: in_range("--jobs", jobs.unwrap_or(cores), 1, 1024)?,
        slurm,
        report_only,
    };
    let path = crate::reproduce::reproduce(&request)?;
    if slurm {
        println!(
            "wrote the job arrays under {}; submit each <study>/runs/sweep.sbatch with sbatch, \
             then run: dustdem reproduce --tier {tier} --out {} --report-only",
            path.display(),
            request.out.display()
        );
    } else {
        println!("wrote {}", path.display());
    }
    Ok(())
}
