//! The calibration commands: `calibrate` (locally or on Slurm job arrays), the hidden
//! `calibrate-run` of those arrays' tasks, and `synth`.

use super::args::{CalibrateArgs, SynthArgs};
use super::progress::release_locks_on_signal;
use crate::calibrate::slurm::{run_request, SlurmRuns};
use crate::calibrate::synth::{write_synth, SynthSpec};
use crate::calibrate::{parse_effect, run_calibration, run_plan, RunCache, Settings};
use crate::config::Config;
use crate::output::lock::lock_dir;
use crate::sweep::slurm_settings::{check_slurm_time, SlurmSettings};
use std::path::{Path, PathBuf};

/// `calibrate --slurm`: what each batch's job array asks for.
struct SlurmRequest {
    time: String,
    mem_mb: u64,
    max_running: u64,
}

/// How `calibrate` uses its run cache directory.
enum CacheUse {
    /// Read what it holds, simulate and store the rest.
    Fill(PathBuf),
    /// Read only (`--cache-only`): a missing run is an error.
    ReadOnly(PathBuf),
}

fn calibrate(
    measured: &[PathBuf],
    config: &Path,
    out: &Path,
    settings: &Settings,
    plan: bool,
    cache: &CacheUse,
    slurm: Option<SlurmRequest>,
) -> Result<(), String> {
    let _lock = lock_dir(out)?;
    // Nothing to checkpoint (finished runs are in the cache): a signal ends the calibration at
    // once, after removing its locks.
    release_locks_on_signal();
    let progress = |line: &str| eprintln!("{line}");
    let cache = match (cache, slurm) {
        (CacheUse::ReadOnly(cache), _) => RunCache::read_only(cache),
        (CacheUse::Fill(cache), None) => RunCache::persistent(cache),
        (CacheUse::Fill(cache), Some(r)) => {
            check_slurm_time(&r.time)?;
            let exe = std::env::current_exe()
                .and_then(|e| e.canonicalize())
                .map_err(|e| format!("cannot find this binary for the job arrays: {e}"))?;
            let cache =
                std::path::absolute(cache).map_err(|e| format!("{}: {e}", cache.display()))?;
            let settings = SlurmSettings {
                time: r.time,
                mem_mb: r.mem_mb,
                max_running: r.max_running,
                ..SlurmSettings::default()
            };
            RunCache::on_slurm(&cache, SlurmRuns { exe, settings })
        }
    };
    let (lines, files) = if plan {
        run_plan(measured, config, out, settings, &cache, &progress)?
    } else {
        run_calibration(measured, config, out, settings, &cache, &progress)?
    };
    for line in lines {
        println!("{line}");
    }
    println!("results in {}:", out.display());
    for f in files {
        println!("  {}", f.display());
    }
    Ok(())
}

/// `dustdem calibrate-run`: one task of a `calibrate --slurm` job array.
pub(super) fn calibrate_run(cache: &Path, request: &Path) -> Result<(), String> {
    println!("{}", run_request(cache, request)?);
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

/// `dustdem calibrate`: the search's settings and the cache and Slurm choices from the
/// command line.
pub(super) fn calibrate_command(a: CalibrateArgs) -> Result<(), String> {
    let cache = a.cache.unwrap_or_else(|| a.out.join("run_cache"));
    let slurm = a.slurm.then_some(SlurmRequest {
        time: a.slurm_time,
        mem_mb: a.slurm_mem_mb,
        max_running: a.slurm_max_running,
    });
    let mut settings = Settings {
        seeds: a.seeds,
        screen_seeds: a.screen_seeds,
        screen_monomers: a.screen_monomers,
        prune: !a.no_prune,
        both_ends: !a.screen_upper_end_only,
        pairs: !a.single_effects_only,
        max_rounds: a.rounds,
        revisit: a.revisit,
        ..Settings::default()
    };
    if let Some(t) = a.threads {
        settings.threads = t;
    }
    let cache = match a.cache_only {
        true => CacheUse::ReadOnly(cache),
        false => CacheUse::Fill(cache),
    };
    calibrate(
        &a.measured,
        &a.config,
        &a.out,
        &settings,
        a.plan,
        &cache,
        slurm,
    )
}

/// `dustdem synth`: the data's specification from the command line.
pub(super) fn synth_command(a: SynthArgs) -> Result<(), String> {
    let spec = SynthSpec {
        geometries: a.geometry,
        sticking: !a.no_sticking,
        seeds: a.seeds,
        pressure_range: (a.p_min, a.p_max),
        points: a.points,
        phi_noise: a.noise,
        sticking_noise: a.sticking_noise,
        noise_seed: a.noise_seed,
    };
    synth(&a.config, &a.effect, &spec, a.threads, &a.out)
}
