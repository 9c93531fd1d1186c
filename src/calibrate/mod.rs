//! Calibration: compare the model with measured data, find where and by how much it misses,
//! and name the physical effect that explains the gap (or say that none, or several, do).
//!
//! `measured` reads the data, `effects` maps named one-parameter effects onto the config,
//! `simulate` makes (and caches) the runs, `gap` measures the difference and its noise,
//! `attribution` fits one effect at a time and decides, `predictor` turns configs into
//! predictions (a screen on common random numbers) and counts their cost, `search` screens,
//! prunes, widens and refines within a round, `workflow` runs the add-and-rerun loop, `synth`
//! writes measured-like data from the simulator, `report` writes the Markdown report and the
//! corrected config, and `figures` the plots (drawn through `output::plot`).

pub mod attribution;
pub mod detection;
pub mod discriminate;
pub mod effects;
pub mod fidelity;
pub mod figures;
pub mod gap;
pub mod grid;
pub mod held_out;
mod leaders;
pub mod measured;
pub mod outside;
pub mod pairs;
pub mod predictor;
pub mod report;
mod report_round;
mod report_tables;
mod revisit;
mod round;
pub mod search;
pub mod simulate;
pub mod slurm;
mod sticking;
mod stored;
pub mod synth;
pub mod workflow;

pub use effects::Effect;
pub use measured::MeasuredSet;
pub use simulate::RunCache;
pub use workflow::{calibrate, Calibration, Settings};

use crate::config::{Config, ConfigError};
use std::path::{Path, PathBuf};

fn load_measured(measured_paths: &[PathBuf]) -> Result<(MeasuredSet, String), String> {
    let sets = measured_paths
        .iter()
        .map(|p| MeasuredSet::load(p).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    if sets.is_empty() {
        return Err("calibrate needs at least one --measured file".into());
    }
    let label = measured_paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    Ok((MeasuredSet::merge(sets), label))
}

/// `dustdem calibrate --plan`: the detection limits of the (planned) data under the config's
/// system size; writes plan.md into `out` and returns the summary lines and the file.
pub fn run_plan(
    measured_paths: &[PathBuf],
    config_path: &Path,
    out: &Path,
    settings: &Settings,
    cache: &RunCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<(Vec<String>, Vec<PathBuf>), String> {
    let (measured, label) = load_measured(measured_paths)?;
    let config = Config::load(config_path).map_err(|e| e.to_string())?;
    let plan = workflow::plan(&measured, &config, settings, cache, progress)?;
    let file = report::write_plan(&plan, out, &label, config_path)?;
    let lines = plan
        .detection
        .iter()
        .map(workflow::describe_limit)
        .collect();
    Ok((lines, vec![file]))
}

/// `dustdem calibrate`: loads the measured files (their curves are fitted jointly) and the
/// config, calibrates, writes the report into `out` and returns the summary lines and the
/// files written.
pub fn run_calibration(
    measured_paths: &[PathBuf],
    config_path: &Path,
    out: &Path,
    settings: &Settings,
    cache: &RunCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<(Vec<String>, Vec<PathBuf>), String> {
    let (measured, label) = load_measured(measured_paths)?;
    let config = Config::load(config_path).map_err(|e| e.to_string())?;
    let cal = calibrate(&measured, &config, settings, cache, progress)?;
    let files = report::write_outputs(&cal, out, &label, config_path)?;
    let mut lines = Vec::new();
    for (k, round) in cal.rounds.iter().enumerate() {
        lines.push(format!(
            "round {}: {}",
            k + 1,
            workflow::describe_decision(&round.decision)
        ));
    }
    for (effect, factor) in &cal.applied {
        lines.push(format!(
            "applied {} x{:.4} ({})",
            effect.name(),
            factor,
            effect.describe_value(&cal.base, *factor)
        ));
    }
    if cal.applied.is_empty() {
        lines.push(
            "no effect applied; these data would have shown (detection limits at 95%):".into(),
        );
        if let Some(first) = cal.rounds.first() {
            lines.extend(first.detection.iter().map(workflow::describe_limit));
        }
    }
    let (before, after) = (cal.baseline_gap(), cal.final_gap());
    lines.push(format!(
        "chi2 {:.2} -> {:.2} (noise threshold {:.2}); normalised gap shrank by {:.0}%; RMS gap \
         of the curves beyond noise shrank by: {}",
        before.chi2,
        after.chi2,
        after.threshold,
        100.0 * report::gap_shrink(before, &after),
        report::describe_curve_shrinks(before, &after)
    ));
    Ok((lines, files))
}

/// Parses `name=factor` (e.g. `rolling_stiffness=8`) as an effect and its factor.
pub fn parse_effect(text: &str) -> Result<(Effect, f64), ConfigError> {
    let allowed = format!(
        "name=factor with a factor > 0 and a name from: {}",
        Effect::ALL.map(|e| e.name()).join(", ")
    );
    let fail = || ConfigError {
        file: "command line".into(),
        field: "--effect".into(),
        value: text.into(),
        allowed: allowed.clone(),
    };
    let (name, factor) = text.split_once('=').ok_or_else(fail)?;
    let effect = Effect::from_name(name.trim()).ok_or_else(fail)?;
    let factor: f64 = factor.trim().parse().map_err(|_| fail())?;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(fail());
    }
    Ok((effect, factor))
}
