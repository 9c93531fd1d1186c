//! The dustdem command line: `args` (the grammar), `commands` (what each subcommand does),
//! `progress` (bars, log lines, signals, summaries). `main.rs` only calls [`main`].

mod args;
mod calibration;
mod commands;
mod progress;

use crate::bench::Options as BenchOptions;
use crate::calibrate::synth::SynthSpec;
use crate::calibrate::Settings;
use crate::job::{Backend, PrivateRuntimeDir};
use args::{Cli, Command, SweepAction};
use calibration::{calibrate, calibrate_run, synth, CacheUse, SlurmRequest};
use clap::Parser;
use commands::{
    bench, fit, generate, info, reproduce, resume, run, sweep, sweep_analyze, sweep_collect,
};
use std::process::ExitCode;

/// Parses the command line and runs the command; errors are printed, exit status 2
/// ([`crate::RESUMABLE_EXIT`] where a signal stopped it at a checkpoint).
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    // A bad lane choice is refused before anything runs (the engine would fall back silently).
    if let Err(e) = crate::backend::cpu::lanes::ContactLanes::from_env() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    // Only these look for a GPU (`--backend cpu` never does). Before any thread starts.
    let probes = match &cli.command {
        Command::Run { backend, .. } | Command::Resume { backend, .. } => *backend != Backend::Cpu,
        Command::Info { .. } => true,
        Command::Bench { backends, .. } => backends.contains("gpu"),
        _ => false,
    };
    let _runtime_dir = (probes && !cli.verbose)
        .then(PrivateRuntimeDir::ensure)
        .flatten();
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
        Command::ConfigReference => {
            print!("{}", crate::config::reference::render_markdown());
            Ok(())
        }
        Command::Calibrate {
            measured,
            config,
            out,
            seeds,
            screen_seeds,
            screen_monomers,
            no_prune,
            screen_upper_end_only,
            single_effects_only,
            rounds,
            revisit,
            threads,
            plan,
            cache,
            cache_only,
            slurm,
            slurm_time,
            slurm_mem_mb,
            slurm_max_running,
        } => {
            let cache = cache.unwrap_or_else(|| out.join("run_cache"));
            let slurm = slurm.then_some(SlurmRequest {
                time: slurm_time,
                mem_mb: slurm_mem_mb,
                max_running: slurm_max_running,
            });
            let mut settings = Settings {
                seeds,
                screen_seeds,
                screen_monomers,
                prune: !no_prune,
                both_ends: !screen_upper_end_only,
                pairs: !single_effects_only,
                max_rounds: rounds,
                revisit,
                ..Settings::default()
            };
            if let Some(t) = threads {
                settings.threads = t;
            }
            let cache = match cache_only {
                true => CacheUse::ReadOnly(cache),
                false => CacheUse::Fill(cache),
            };
            calibrate(&measured, &config, &out, &settings, plan, &cache, slurm)
        }
        Command::CalibrateRun { cache, request } => calibrate_run(&cache, &request),
        Command::Bench {
            sizes,
            seconds,
            rounds,
            threads,
            backends,
            lammps,
            sample_order,
            untallied,
            samples,
            prepare_speed,
            out,
        } => BenchOptions::parse(&sizes, seconds, rounds, &threads, &backends, lammps, out)
            .and_then(|o| o.with_samples(&samples, prepare_speed))
            .and_then(|o| {
                bench(BenchOptions {
                    sample_order,
                    untallied,
                    // This executable runs the whole runs of `--lammps`.
                    dustdem_exe: std::env::current_exe().ok(),
                    ..o
                })
            }),
        Command::Sweep {
            action: Some(SweepAction::Collect { dir }),
            ..
        } => sweep_collect(&dir),
        Command::Sweep {
            action: Some(SweepAction::Analyze { dir }),
            ..
        } => sweep_analyze(&dir),
        Command::Reproduce {
            tier,
            out,
            runs,
            jobs,
            slurm,
            report_only,
        } => reproduce(tier, out, runs, jobs, slurm, report_only),
        Command::Sweep {
            action: None,
            sweep: file,
            out,
            jobs,
            threads,
            backend,
            precision,
            slurm,
            case,
            time,
            mem_mb,
        } => sweep(commands::SweepRequest {
            file: file.expect("clap requires the sweep file"),
            out,
            jobs,
            threads,
            backend,
            precision,
            slurm,
            case,
            time,
            mem_mb,
        }),
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
            if progress::stopped_at_checkpoint() {
                ExitCode::from(crate::RESUMABLE_EXIT)
            } else {
                ExitCode::from(2)
            }
        }
    }
}
