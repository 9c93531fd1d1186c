//! The command line's grammar: subcommands, their arguments and help texts (clap).

use crate::calibrate::measured::Geometry;
use crate::job::{Backend, PrecisionChoice};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "dustdem",
    version,
    about = "Molecular dynamics of porous dust agglomerates"
)]
pub(super) struct Cli {
    /// Let the libraries behind the GPU probe (Vulkan loader, Mesa's layers, drivers) print
    /// on stderr; otherwise the probe gets a private XDG_RUNTIME_DIR where none is usable,
    /// which keeps their display-related messages away.
    #[arg(short, long, global = true)]
    pub(super) verbose: bool,
    #[command(subcommand)]
    pub(super) command: Command,
}

#[derive(Subcommand)]
pub(super) enum Command {
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
    /// Print the config reference as Markdown: every key with its unit, default, allowed
    /// values and meaning (docs/guide/src/config-reference.md is this output).
    ConfigReference,
    /// Compare a config with measured data and name the effect that explains the gap; writes
    /// report.md, calibration.png and corrected.toml.
    Calibrate(CalibrateArgs),
    /// One run of a `calibrate --slurm` job array (used by its script): makes the run a
    /// request file names and stores it in the run cache.
    #[command(hide = true)]
    CalibrateRun {
        #[arg(long)]
        cache: PathBuf,
        #[arg(long)]
        request: PathBuf,
    },
    /// Measure particle-steps per second of the engines (and of LAMMPS with --lammps) on RBD
    /// samples under 1 m/s omnidirectional compression; writes bench.md and bench.csv.
    Bench(BenchArgs),
    /// Run a parameter sweep: every combination of the sweep file's wall speeds, seeds, model
    /// variants and sample sizes, each case an ordinary run directory; finished cases are
    /// skipped, interrupted ones resumed from their checkpoint. `sweep collect DIR` merges the
    /// cases' results into DIR/sweep.csv.
    #[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
    Sweep(SweepArgs),
    /// Reproduce the results of Seizinger et al. (2012): quasi-static and dynamic
    /// omnidirectional and unidirectional sweeps, analysed and gathered into
    /// OUT/REPRODUCTION.md beside the paper's numbers. Running it again resumes the sweeps.
    Reproduce {
        /// smoke (a minute, tests the pipeline), quick (about an hour on two cores, scaled-down
        /// samples) or paper (the dynamic study at the paper's size, the slow studies at sizes
        /// two cores finish beside the paper's: accumulates over runs, a cluster or a GPU).
        #[arg(long, value_enum, default_value = "quick")]
        tier: crate::reproduce::Tier,
        #[arg(long, default_value = "reproduction")]
        out: PathBuf,
        /// Where the sweeps run, one directory per study (default: OUT/<study>/runs). Only
        /// the compact store of finished cases is kept under OUT.
        #[arg(long)]
        runs: Option<PathBuf>,
        /// Cases at once in each sweep (1 to 1024; default: the logical CPUs).
        #[arg(long)]
        jobs: Option<usize>,
        /// Write the three sweeps' Slurm job arrays instead of running (then, once they ran:
        /// `dustdem reproduce --report-only` with the same --tier and --out).
        #[arg(long, conflicts_with = "report_only")]
        slurm: bool,
        /// Run nothing: store the cases that finished (if the runs directory exists) and
        /// write REPRODUCTION.md from the store.
        #[arg(long)]
        report_only: bool,
    },
    /// Write measured-like data from the simulator, with effects switched on and noise added.
    Synth(SynthArgs),
}

#[derive(Subcommand)]
pub(super) enum SweepAction {
    /// Merge what a sweep's cases wrote into DIR/sweep.csv (one row per case: parameters,
    /// status, final phi and pressure, wall-clock seconds, curve path) and name the cases that
    /// are missing, failed or unfinished (exit status 2 if any).
    Collect {
        /// The sweep's output directory.
        dir: PathBuf,
    },
    /// Collect, then analyse the finished cases as Seizinger et al. (2012) do: seeds averaged
    /// per (variant, size, speed), Eq. 13 per speed, p_m(v) and Δ(v), the compaction-front
    /// speed, the regimes of dynamic curves; writes DIR/analysis.md, analysis.png and
    /// analysis.svg (all figures, three a row) and one SVG per figure.
    Analyze {
        /// The sweep's output directory.
        dir: PathBuf,
    },
}

#[derive(clap::Args)]
pub(super) struct ReportArgs {
    /// Print only the summary.
    #[arg(long)]
    pub(super) quiet: bool,
    /// One `key=value` line per row on stderr instead of a progress bar (for scripts and
    /// cluster logs).
    #[arg(long)]
    pub(super) log_lines: bool,
    /// Threads of the CPU engine (1 to 1024; default: all cores). Any count gives the same
    /// bits.
    #[arg(long)]
    pub(super) threads: Option<usize>,
    /// Arithmetic of the GPU engine: exact (f64, the CPU reference's bits; adapters without f64
    /// are refused), mixed (f32 with split centres and double-f32 pointers, wall points and
    /// tallies: runs on every adapter) or auto (exact where the adapter has f64, else mixed).
    #[arg(long, default_value = "auto")]
    pub(super) precision: PrecisionChoice,
}

// The arguments of `dustdem calibrate`.
#[derive(Args)]
pub(super) struct CalibrateArgs {
    /// Measured-data file (see configs/measured/); repeat it to fit the curves of several
    /// files jointly.
    #[arg(long, required = true)]
    pub(super) measured: Vec<PathBuf>,
    /// Base config: material, model, sample size, wall speed, time step.
    #[arg(long)]
    pub(super) config: PathBuf,
    #[arg(long, default_value = "runs/calibration")]
    pub(super) out: PathBuf,
    /// RBD sample seeds; each compression curve is simulated once per seed for the
    /// baseline and for every correction kept.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3")]
    pub(super) seeds: Vec<u64>,
    /// Seeds of the screen and the 1-D fits: the first N of --seeds, compared with the
    /// current model on the same samples (common random numbers); 0: every seed.
    #[arg(long, default_value_t = 1)]
    pub(super) screen_seeds: usize,
    /// Sample size of the screen and the 1-D fits (multi-fidelity in size), smaller than
    /// the config's; the baseline, the polished fits, the gaps and the detection limits of
    /// a gap within noise stay at the config's size. 0: the config's size.
    #[arg(long, default_value_t = 0)]
    pub(super) screen_monomers: usize,
    /// Widen and refine every effect, also those that cannot come within Δχ² = 2 of the
    /// best after the screen.
    #[arg(long)]
    pub(super) no_prune: bool,
    /// Screen every effect at the upper end of its range only (the search before both ends
    /// were screened: an effect is then pruned on its scaled response, which is no bound).
    #[arg(long)]
    pub(super) screen_upper_end_only: bool,
    /// Single effects only: no joint fits of pairs and no proposed discriminating
    /// measurement (the search before pairs, which the committed real-data calibrations
    /// were made with).
    #[arg(long)]
    pub(super) single_effects_only: bool,
    /// Effects added one after the other at most.
    #[arg(long, default_value_t = 2)]
    pub(super) rounds: usize,
    /// After the rounds, search again for each applied effect but the last with all the
    /// others in, and let a better fit replace it (then the last one too).
    #[arg(long)]
    pub(super) revisit: bool,
    /// Simulation threads (default: all cores).
    #[arg(long)]
    pub(super) threads: Option<usize>,
    /// Only estimate what the (planned) data and the config's system size can resolve:
    /// the baseline and a screen of every effect, no fit; writes plan.md.
    #[arg(long)]
    pub(super) plan: bool,
    /// Where finished runs are kept, so a repeated or interrupted calibration does not
    /// repeat them (default: OUT/run_cache).
    #[arg(long)]
    pub(super) cache: Option<PathBuf>,
    /// Only read the run cache: a run it does not hold is an error, never simulated
    /// (rebuilds a report from a committed cache).
    #[arg(long, conflicts_with = "slurm")]
    pub(super) cache_only: bool,
    /// Make each batch of runs a step needs as a Slurm job array over the run cache (one
    /// run per task; `sbatch --wait`), then go on; the result is the local calibration's.
    #[arg(long)]
    pub(super) slurm: bool,
    /// Time limit of each array task (Slurm's format).
    #[arg(long, default_value = "01:00:00", requires = "slurm")]
    pub(super) slurm_time: String,
    /// Memory per array task [MB].
    #[arg(long, default_value_t = 2000, requires = "slurm")]
    pub(super) slurm_mem_mb: u64,
    /// At most this many array tasks at once (0: no limit).
    #[arg(long, default_value_t = 0, requires = "slurm")]
    pub(super) slurm_max_running: u64,
}

// The arguments of `dustdem bench`.
#[derive(Args)]
pub(super) struct BenchArgs {
    /// Sample sizes N, comma-separated (10 to 10000000).
    #[arg(long, default_value = "1000,10000,100000,1000000")]
    pub(super) sizes: String,
    /// Target wall-clock seconds of one measurement (0.05 to 3600); the steps follow from
    /// a short timed probe of each engine.
    #[arg(long, default_value_t = 20.0)]
    pub(super) seconds: f64,
    /// Rounds; each runs every engine once in turn from the same starting state (1 to 100).
    #[arg(long, default_value_t = 3)]
    pub(super) rounds: usize,
    /// CPU engine thread counts, comma-separated: numbers or `all`.
    #[arg(long, default_value = "1,all")]
    pub(super) threads: String,
    /// Engines: cpu, gpu (exact precision; skipped with a note where no adapter has f64)
    /// and gpu-mixed (the mixed precision, on any adapter), comma-separated.
    #[arg(long, default_value = "cpu,gpu")]
    pub(super) backends: String,
    /// Also export the sample and an input deck for LAMMPS and, where `lmp` is on PATH,
    /// run it on 1 and 2 MPI ranks.
    #[arg(long)]
    pub(super) lammps: bool,
    /// Also time the CPU engine on all threads with the monomers stored in the sample's
    /// order instead of the space-filling order, to show what that order gains.
    #[arg(long)]
    pub(super) sample_order: bool,
    /// Also time the CPU engine on all threads without booking the inelastic corrections'
    /// dissipation (`[output] tally_corrections = false`), with its ratio to LAMMPS.
    #[arg(long)]
    pub(super) untallied: bool,
    /// Starting states, comma-separated: `fresh` (the RBD sample) and filling factors
    /// (0.16 to 0.6) the engine first compresses the sample to, e.g. `fresh,0.3,0.45`;
    /// compressed states are stored under <out>/states and reused.
    #[arg(long, default_value = "fresh")]
    pub(super) samples: String,
    /// Top wall speed [m/s] that compresses the compressed states (0.01 to 25); their
    /// measurement goes on at this speed (the fresh sample's at 1 m/s).
    #[arg(long, default_value_t = 1.0)]
    pub(super) prepare_speed: f64,
    #[arg(long, default_value = "bench")]
    pub(super) out: PathBuf,
}

// The arguments of `dustdem synth`.
#[derive(Args)]
pub(super) struct SynthArgs {
    /// Base config (sample size, wall speed, time step, model).
    #[arg(long)]
    pub(super) config: PathBuf,
    /// An effect and its factor, e.g. rolling_stiffness=8 (repeatable).
    #[arg(long)]
    pub(super) effect: Vec<String>,
    /// Compression curves to write: omni, uni, or both as omni,uni.
    #[arg(long, value_delimiter = ',', default_value = "omni")]
    pub(super) geometry: Vec<Geometry>,
    /// Leave out the sticking velocity.
    #[arg(long)]
    pub(super) no_sticking: bool,
    /// RBD sample seeds averaged per curve.
    #[arg(long, value_delimiter = ',', default_value = "101,102,103")]
    pub(super) seeds: Vec<u64>,
    #[arg(long, default_value_t = 1e2)]
    pub(super) p_min: f64,
    #[arg(long, default_value_t = 1e5)]
    pub(super) p_max: f64,
    /// Points per curve.
    #[arg(long, default_value_t = 10)]
    pub(super) points: usize,
    /// 1-sigma noise added to each filling factor.
    #[arg(long, default_value_t = 0.005)]
    pub(super) noise: f64,
    /// Relative 1-sigma noise of the sticking velocity.
    #[arg(long, default_value_t = 0.05)]
    pub(super) sticking_noise: f64,
    #[arg(long, default_value_t = 1)]
    pub(super) noise_seed: u64,
    #[arg(long)]
    pub(super) out: PathBuf,
    #[arg(long)]
    pub(super) threads: Option<usize>,
}

// The arguments of `dustdem sweep`.
#[derive(Args)]
pub(super) struct SweepArgs {
    #[command(subcommand)]
    pub(super) action: Option<SweepAction>,
    /// The sweep file (see configs/sweep_example.toml).
    #[arg(required = true)]
    pub(super) sweep: Option<PathBuf>,
    /// Output directory (overrides the sweep file's `out`; default runs/<sweep file name>).
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Cases run at once (1 to 1024).
    #[arg(long)]
    pub(super) jobs: Option<usize>,
    /// Threads of each case's CPU engine (1 to 1024; default: the cores divided among the
    /// jobs; with --slurm: 1). Any count gives the same bits.
    #[arg(long)]
    pub(super) threads: Option<usize>,
    /// Engine of each case: cpu, gpu or auto (as for `run`).
    #[arg(long, default_value = "auto")]
    pub(super) backend: Backend,
    /// Arithmetic of each case's GPU engine: exact, mixed or auto (as for `run`).
    #[arg(long, default_value = "auto")]
    pub(super) precision: crate::job::PrecisionChoice,
    /// Do not run: write DIR/sweep.sbatch, a Slurm job array with one case per task, and
    /// DIR/cases.csv.
    #[arg(long)]
    pub(super) slurm: bool,
    /// Run only the case of this index (0-based, the order of cases.csv): what each array
    /// task of sweep.sbatch does.
    #[arg(long, conflicts_with = "slurm")]
    pub(super) case: Option<usize>,
    /// With --slurm: time limit per task (overrides [slurm] time), e.g. 02:00:00.
    #[arg(long, requires = "slurm")]
    pub(super) time: Option<String>,
    /// With --slurm: memory per task in MB (overrides [slurm] mem_mb).
    #[arg(long, requires = "slurm")]
    pub(super) mem_mb: Option<u64>,
}
