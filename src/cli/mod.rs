//! The dustdem command line: `args` (the grammar), `commands` (what each subcommand does),
//! `progress` (bars, log lines, signals, summaries). `main.rs` only calls [`main`].

mod args;
mod calibration;
mod commands;
mod progress;
mod sweep;

use crate::job::{Backend, PrivateRuntimeDir};
use args::{Cli, Command, SweepAction, SweepArgs};
use calibration::{calibrate_command, calibrate_run, synth_command};
use clap::Parser;
use commands::{bench_command, fit, generate, info, reproduce, resume, run};
use std::process::ExitCode;
use sweep::{sweep_analyze, sweep_collect, sweep_command};

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
        Command::Bench(args) => args.backends.contains("gpu"),
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
        Command::Calibrate(args) => calibrate_command(args),
        Command::CalibrateRun { cache, request } => calibrate_run(&cache, &request),
        Command::Bench(args) => bench_command(args),
        Command::Sweep(SweepArgs {
            action: Some(SweepAction::Collect { dir }),
            ..
        }) => sweep_collect(&dir),
        Command::Sweep(SweepArgs {
            action: Some(SweepAction::Analyze { dir }),
            ..
        }) => sweep_analyze(&dir),
        Command::Sweep(args) => sweep_command(args),
        Command::Reproduce {
            tier,
            out,
            runs,
            jobs,
            slurm,
            report_only,
        } => reproduce(tier, out, runs, jobs, slurm, report_only),
        Command::Synth(args) => synth_command(args),
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
