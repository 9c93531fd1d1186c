//! `dustdem bench`: particle-steps per second of the engines on RBD samples under 1 m/s
//! omnidirectional compression, as a table (bench.md, bench.csv), optionally beside LAMMPS
//! running the same sample and the nearest granular model it has.
//!
//! The machine this runs on may be shared and noisy, so the measurements are arranged for
//! ratios: per N, every engine ("side") starts from the same warmed-up state, and each round
//! runs every side once in turn, so the sides of one round meet the same load. Rates are
//! medians over rounds; ratios are medians of the per-round ratios with their range.
//!
//! Here: the plan per N (sample, warm-up, steps, rounds). `options` checks the arguments,
//! `measure` times one side, `table` writes the files, `lammps` exports and runs the deck,
//! `whole_run` times whole `dustdem run` and `lmp` processes.

pub mod lammps;
pub mod measure;
pub mod memory;
pub mod options;
pub mod prepare;
mod size;
pub mod stats;
pub mod table;
pub mod whole_run;

pub use options::{Options, SampleState, Threads};

use crate::backend::cpu::CpuEngine;
use crate::backend::gpu::context::GpuContext;
use crate::backend::gpu::shader::Precision;
use crate::config::Config;
use crate::experiment::setup::{build_sample, build_walls, stored_monomers};
use crate::output::atomic::write_atomic;
use lammps::Lammps;
use measure::{sides, Side, SideKind};
use size::measure_size;
use std::path::PathBuf;

/// The benchmark's compression of `n` monomers: the project's defaults (Seizinger et al.'s
/// unmodified model, dt 0.3 ns) with an RBD sample of seed 1 and the top wall at 1 m/s.
pub fn benchmark_config(n: usize) -> Result<Config, String> {
    Config::parse(&benchmark_config_text(n), "benchmark").map_err(|e| e.to_string())
}

/// [`benchmark_config`] as a config file's text (its `[experiment]` table last).
pub fn benchmark_config_text(n: usize) -> String {
    format!(
        "[sample]\nmonomers = {n}\nseed = 1\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 1.0\n"
    )
}

/// The engine of [`benchmark_config`]`(n)` at time 0, with the sample and walls it was made
/// from (the LAMMPS export needs them).
pub fn benchmark_engine(
    config: &Config,
) -> Result<(CpuEngine, crate::sample::Sample, Vec<crate::state::Wall>), String> {
    let law = config.contact_law();
    let sample = build_sample(config, &law).map_err(|e| e.to_string())?;
    let walls = build_walls(config, &law, &sample).map_err(|e| e.to_string())?;
    let engine = CpuEngine::new(
        law,
        config.dt(),
        stored_monomers(config, &sample),
        walls.clone(),
        config.integration.pair_slots,
        config.integration.wall_slots,
    )
    .map_err(|e| e.to_string())?;
    Ok((engine, sample, walls))
}

/// Everything measured, for the tables.
#[derive(Clone, Debug)]
pub struct Report {
    pub options: Options,
    pub sides: Vec<Side>,
    pub sizes: Vec<SizeResult>,
    /// CPU model and logical CPUs.
    pub host: String,
    /// The GPU adapter the gpu side ran on (name, type, float mode).
    pub gpu_adapter: Option<String>,
    /// LAMMPS's version line, from its first log.
    pub lammps_version: Option<String>,
    /// Sides skipped and why, and other remarks, one line each.
    pub notes: Vec<String>,
}

/// One N.
#[derive(Clone, Debug)]
pub struct SizeResult {
    pub n: usize,
    /// The state the measurement started from before its warm-up.
    pub sample: SampleState,
    /// Filling factor by the wall gap at the measured starting state.
    pub phi: f64,
    /// Steps run before the measured state (dustdem's warm-up; LAMMPS runs as many first).
    pub warmup_steps: u64,
    /// 2 × pair contacts / N of the measured starting state.
    pub contacts_per_monomer: f64,
    /// One per [`Report::sides`], in the same order.
    pub sides: Vec<SideResult>,
    /// Peak resident memory of this process while this N ran [B].
    pub peak_rss_bytes: Option<u64>,
    /// Whether the peak was reset before this N (otherwise it covers the earlier N too).
    pub peak_rss_per_size: bool,
    /// LAMMPS's overlapping pairs per monomer at the end of its one-rank runs.
    pub lammps_contacts_per_monomer: Option<f64>,
    /// `dustdem run` against `lmp`, whole processes (fresh samples with `--lammps`).
    pub whole_run: Option<whole_run::WholeRun>,
}

/// One side at one N.
#[derive(Clone, Debug, Default)]
pub struct SideResult {
    pub steps: u64,
    /// Particle-steps per second, one per round.
    pub rates: Vec<f64>,
    /// Seconds per step of each of [`Side::pass_names`] (mean over the rounds); empty where
    /// the side does not report them.
    pub passes: Vec<f64>,
    /// Memory the side reports [MiB]: GPU buffers, or LAMMPS's largest per-rank allocation.
    pub memory_mib: Option<f64>,
    /// Why the side was not measured (or stopped being measured).
    pub skipped: Option<String>,
}

/// What the sides need across sizes: thread pools, the GPU's availability, LAMMPS.
struct Setup {
    pools: Vec<Option<rayon::ThreadPool>>,
    /// All threads, for the warm-up.
    warm_pool: rayon::ThreadPool,
    /// Per GPU side's precision: whether a device for it could be made.
    gpu: Vec<(Precision, Result<(), String>)>,
    lammps: Result<Lammps, String>,
}

impl Setup {
    fn gpu_ready(&self, precision: Precision) -> &Result<(), String> {
        &self
            .gpu
            .iter()
            .find(|(p, _)| *p == precision)
            .expect("a GPU side is made for each precision asked for")
            .1
    }
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("a pool of {threads} threads: {e}"))
}

/// Runs the benchmark and writes bench.md and bench.csv into `options.out` (again after every
/// N, so an interrupted run keeps what it measured). `progress` gets one line per step of
/// the plan.
pub fn run_bench(options: &Options, progress: &dyn Fn(&str)) -> Result<Report, String> {
    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("--out {}: {e}", options.out.display()))?;
    let sides = sides(options);
    let mut report = Report {
        options: options.clone(),
        sides: sides.clone(),
        sizes: Vec::new(),
        host: host(),
        gpu_adapter: None,
        lammps_version: None,
        notes: Vec::new(),
    };
    let mut gpu = Vec::new();
    for &precision in &options.gpu {
        let ready = match GpuContext::new(&measure::gpu_requirements(precision)) {
            Ok(ctx) => {
                let s = ctx.summary();
                report.gpu_adapter = Some(format!(
                    "{} ({:?}; {:?} float mode)",
                    s.name, s.device_type, ctx.float_mode
                ));
                Ok(())
            }
            Err(e) => Err(format!(
                "gpu ({} precision) not measured: {e}",
                precision.name()
            )),
        };
        if let Err(note) = &ready {
            progress(note);
            report.notes.push(note.clone());
        }
        gpu.push((precision, ready));
    }
    let lammps = if options.lammps {
        Lammps::find()
    } else {
        Err(String::new())
    };
    if let (true, Err(note)) = (options.lammps, &lammps) {
        progress(note);
        report.notes.push(format!(
            "{note}; the deck and data file are written all the same"
        ));
    }
    let pools = sides
        .iter()
        .map(|s| match s.kind {
            SideKind::Cpu(t) | SideKind::CpuSampleOrder(t) | SideKind::CpuUntallied(t) => {
                pool(t.resolve()).map(Some)
            }
            _ => Ok(None),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let setup = Setup {
        pools,
        warm_pool: pool(Threads::All.resolve())?,
        gpu,
        lammps,
    };
    for &n in &options.sizes {
        for &sample in &options.samples {
            let result = measure_size(n, sample, options, &sides, &setup, &mut report, progress)?;
            report.sizes.push(result);
            write_tables(&report)?;
        }
    }
    if options.sizes.is_empty() {
        write_tables(&report)?;
    }
    Ok(report)
}

/// bench.md and bench.csv in the output directory.
pub fn write_tables(report: &Report) -> Result<Vec<PathBuf>, String> {
    let out = &report.options.out;
    let mut written = Vec::new();
    for (name, text) in [
        ("bench.md", table::markdown(report)),
        ("bench.csv", table::csv(report)),
    ] {
        let path = out.join(name);
        write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

/// "AMD EPYC …, 2 logical CPUs" from /proc/cpuinfo where there is one, and which instructions
/// evaluate the CPU engine's contact law (`forces_lanes::ContactLanes`).
pub fn host() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let lanes = crate::backend::cpu::lanes::ContactLanes::chosen().describe();
    format!(
        "{model}, {} logical CPUs; CPU engine's contact law: {lanes}",
        Threads::All.resolve()
    )
}
