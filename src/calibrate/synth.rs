//! Measured-like data from the simulator: the mean compression curve of a few samples and the
//! sticking velocity, with Gaussian noise added. The file holds only what an experiment gives
//! (pressures, filling factors, uncertainties, speeds), not the model that made it.

use super::gap::Prediction;
use super::measured::{log_spaced, CompressionCurve, Geometry, MeasuredSet, Provenance};
use super::simulate::{compression_config, run_all, sticking_config, Output, Run, RunCache};
use crate::config::Config;
use crate::rng::Rng;

#[derive(Clone, Debug, PartialEq)]
pub struct SynthSpec {
    pub geometries: Vec<Geometry>,
    pub sticking: bool,
    /// RBD seeds averaged per curve.
    pub seeds: Vec<u64>,
    /// Pressure range of the curves [Pa] and points per curve.
    pub pressure_range: (f64, f64),
    pub points: usize,
    /// 1σ noise added to each φ.
    pub phi_noise: f64,
    /// Relative 1σ noise of the sticking velocity.
    pub sticking_noise: f64,
    pub noise_seed: u64,
}

impl Default for SynthSpec {
    fn default() -> Self {
        SynthSpec {
            geometries: vec![Geometry::Omni],
            sticking: true,
            seeds: vec![101, 102, 103],
            pressure_range: (1e2, 1e5),
            points: 10,
            phi_noise: 0.005,
            sticking_noise: 0.05,
            noise_seed: 1,
        }
    }
}

/// Simulates `config` as `spec` says and returns the data set.
pub fn synthesize(
    config: &Config,
    spec: &SynthSpec,
    cache: &RunCache,
    threads: usize,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<MeasuredSet, String> {
    if spec.seeds.is_empty() || spec.points < 2 {
        return Err("synth needs at least one seed and two points per curve".into());
    }
    let (p_lo, p_hi) = spec.pressure_range;
    if !(p_lo > 0.0 && p_hi > p_lo && p_hi.is_finite()) {
        return Err(format!(
            "pressure range {p_lo:e}..{p_hi:e} Pa: need 0 < p_min < p_max"
        ));
    }
    let mut runs = Vec::new();
    for &g in &spec.geometries {
        for &seed in &spec.seeds {
            runs.push(Run::Compression(compression_config(
                config, g, None, seed, p_hi,
            )));
        }
    }
    if spec.sticking {
        runs.push(Run::Sticking(sticking_config(config)));
    }
    progress(&format!("synth: {} run(s)", runs.len()));
    let outputs = run_all(&runs, cache, threads, &|k, n| {
        progress(&format!("  synth: {k}/{n} runs done"))
    });
    let mut outputs = outputs.into_iter();
    let mut rng = Rng::new(spec.noise_seed);
    let pressure = log_spaced(p_lo, p_hi, spec.points);
    let mut compression = Vec::new();
    for &g in &spec.geometries {
        let mut per_seed = Vec::new();
        for _ in &spec.seeds {
            let Output::Envelope(e) = outputs.next().expect("run per seed")? else {
                unreachable!("run order")
            };
            per_seed.push(pressure.iter().map(|&p| e.phi_at(p)).collect::<Vec<_>>());
        }
        compression.push(synthetic_curve(
            config, spec, g, &pressure, &per_seed, &mut rng, progress,
        )?);
    }
    let mut sticking = Vec::new();
    if spec.sticking {
        let Output::Sticking(v) = outputs.next().expect("sticking run")? else {
            unreachable!("run order")
        };
        sticking.push(super::measured::StickingVelocity {
            name: "sticking (synthetic)".into(),
            velocity: v * (1.0 + spec.sticking_noise * rng.normal()),
            sigma: spec.sticking_noise * v,
        });
    }
    Ok(MeasuredSet {
        source: provenance(config, spec),
        compression,
        sticking,
    })
}

/// The data curve of geometry `g`: the mean of the samples' φ at `pressure` (clipped to the
/// pressures every sample reached) with noise added, σ from the samples' scatter and the noise.
fn synthetic_curve(
    config: &Config,
    spec: &SynthSpec,
    g: Geometry,
    pressure: &[f64],
    per_seed: &[Vec<f64>],
    rng: &mut Rng,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<CompressionCurve, String> {
    let Prediction::Compression { phi, scatter, .. } = Prediction::from_seeds(per_seed) else {
        unreachable!("compression prediction")
    };
    // Clip to the pressures every sample reached, with a warning, rather than fail: the
    // data then cover what the simulation could show.
    let reached = phi.iter().position(|v| !v.is_finite()).unwrap_or(phi.len());
    if reached < 2 {
        return Err(format!(
            "the {} simulation did not reach {:.3e} Pa (two points are needed); lower the \
             pressure range",
            g.name(),
            pressure[reached.min(1)]
        ));
    }
    if reached < phi.len() {
        progress(&format!(
            "warning: synth: the {} simulation did not reach {:.3e} Pa in every sample; the \
             curve is clipped to its first {reached} of {} points (up to {:.3e} Pa)",
            g.name(),
            pressure[reached],
            phi.len(),
            pressure[reached - 1]
        ));
    }
    let (phi, scatter) = (&phi[..reached], &scatter[..reached]);
    let n = spec.seeds.len() as f64;
    Ok(CompressionCurve {
        name: format!("{} (synthetic)", g.name()),
        geometry: g,
        pressure: pressure[..reached].to_vec(),
        phi: phi
            .iter()
            .map(|&v| v + spec.phi_noise * rng.normal())
            .collect(),
        phi_sigma: scatter
            .iter()
            .map(|&s| {
                (s * s / n + spec.phi_noise * spec.phi_noise)
                    .sqrt()
                    .max(1e-4)
            })
            .collect(),
        wall_speed: Some(config.experiment.wall_speed_m_s),
    })
}

/// What the data file says about itself: how it was made, not the model that made it.
fn provenance(config: &Config, spec: &SynthSpec) -> Provenance {
    let (p_lo, p_hi) = spec.pressure_range;
    Provenance {
        citation: "synthetic (dustdem synth)".into(),
        what: format!(
            "mean of {} RBD samples of {} monomers per curve, wall at {} m/s, with Gaussian \
         noise of {} in phi and {}% in the sticking velocity",
            spec.seeds.len(),
            config.sample.monomers,
            config.experiment.wall_speed_m_s,
            spec.phi_noise,
            100.0 * spec.sticking_noise
        ),
        notes: format!(
            "pressures {p_lo:e} to {p_hi:e} Pa; the model that made these data is not recorded"
        ),
    }
}

/// `dustdem synth`: `config` with `effects` applied, simulated as `spec` says, written to
/// `out` as a measured-data file.
pub fn write_synth(
    config: &Config,
    effects: &[(super::Effect, f64)],
    spec: &SynthSpec,
    threads: usize,
    out: &std::path::Path,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<MeasuredSet, String> {
    let mut c = config.clone();
    for &(effect, factor) in effects {
        c = effect.apply(&c, factor);
    }
    let set = synthesize(&c, spec, &RunCache::new(), threads, progress)?;
    let text = format!(
        "# Measured-like data written by dustdem synth.\n{}",
        set.to_toml()
    );
    crate::output::atomic::write_atomic(out, text.as_bytes())
        .map_err(|e| format!("{}: {e}", out.display()))?;
    Ok(set)
}
