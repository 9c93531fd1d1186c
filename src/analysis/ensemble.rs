//! A seed ensemble of omnidirectional runs read the way Seizinger et al. (2012) average "the
//! results of six independent runs": the top-wall pressure averaged over the seeds at fixed
//! filling factor. In the box φ = N V_mono / (A h) is fixed by the wall's position, so every
//! seed passes the same φ at the same time and the average at fixed φ is the average at fixed
//! time; the pressure spikes of a dense layer reaching the bottom survive it, as in the
//! paper's Figs. 11–12. (The calibration and `sweep analyze` read φ at the first passage of a
//! pressure instead; [`crate::analysis::average`] does that.)
//!
//! Eq. 13 is fitted to the seed-mean curve; its error is the seed-to-seed one: the same fit
//! on each seed alone, the standard error of those values, widened by Student's t for the
//! number of seeds so that the interval covers the infinite-ensemble value in 68 % of cases.

#[cfg(test)]
mod tests;

use super::average::spread;
use super::fit::{fit_eq13, Eq13, FitError, FitOptions, FitResult};
use super::run_files::CurveTable;

/// One filling factor of an ensemble average.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedPhiPoint {
    pub phi: f64,
    /// Mean top-wall pressure over the seeds [Pa].
    pub p_mean: f64,
    /// Seed-to-seed standard deviation of the pressure (NaN for one seed).
    pub p_sd: f64,
}

/// The pressure of one run when its filling factor was `phi`: linear interpolation between
/// the two rows around the first passage of `phi` (rows in time order). `None` if the run
/// never reached `phi` or a row around it has no pressure.
pub fn pressure_at_phi(run: &CurveTable, phi: f64) -> Option<f64> {
    let k = run.phi.iter().position(|&f| f >= phi)?;
    if k == 0 {
        return None;
    }
    let (f0, f1) = (run.phi[k - 1], run.phi[k]);
    let (p0, p1) = (run.p_top_pa[k - 1], run.p_top_pa[k]);
    if !(p0.is_finite() && p1.is_finite()) {
        return None;
    }
    let t = if f1 > f0 { (phi - f0) / (f1 - f0) } else { 1.0 };
    Some(p0 + t * (p1 - p0))
}

/// Filling factors from `lo` to `hi` in steps of `step`.
pub fn phi_grid(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step + 1e-9).floor() as usize;
    (0..=n).map(|k| lo + k as f64 * step).collect()
}

/// The seeds' mean pressure at each grid φ that every run reached.
pub fn average_at_fixed_phi(runs: &[&CurveTable], grid: &[f64]) -> Vec<FixedPhiPoint> {
    grid.iter()
        .filter_map(|&phi| {
            let p: Option<Vec<f64>> = runs.iter().map(|r| pressure_at_phi(r, phi)).collect();
            let s = spread(&p?)?;
            Some(FixedPhiPoint {
                phi,
                p_mean: s.mean,
                p_sd: s.sd,
            })
        })
        .collect()
}

/// Two-sided 68.27 % quantile of Student's t with `dof` degrees of freedom: tabulated up to
/// 9, above that the Cornish–Fisher series about the normal quantile z = 1 (Abramowitz &
/// Stegun 26.7.5: t = z + g₁/ν + g₂/ν² + g₃/ν³ + …, at z = 1: g = 1/2, 1/4, 1/16), within
/// 1e-6 of the exact quantile from ν = 10 on (the next term is −0.0057/ν⁴).
pub fn student_t68(dof: usize) -> f64 {
    const T: [f64; 10] = [
        f64::NAN,
        1.837,
        1.321,
        1.197,
        1.142,
        1.111,
        1.091,
        1.077,
        1.067,
        1.059,
    ];
    if dof < T.len() {
        return T[dof];
    }
    let v = dof as f64;
    1.0 + 0.5 / v + 0.25 / v.powi(2) + 0.0625 / v.powi(3)
}

/// Which parameters of Eq. 13 are held.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Held {
    pub phi1: Option<f64>,
    pub phi2: Option<f64>,
}

/// Eq. 13 fitted to an ensemble, with seed-to-seed errors.
#[derive(Clone, Debug, PartialEq)]
pub struct EnsembleFit {
    /// The fit to the seed-mean curve.
    pub mean_fit: FitResult,
    /// 68 % half-widths from the per-seed fits (zero for held parameters; NaN with one seed
    /// or when a seed's fit failed). The p_m entry is p_m · ln 10 · σ(log₁₀ p_m).
    pub err: Eq13,
    pub err_log10_pm: f64,
    /// Seeds whose own fit succeeded.
    pub seeds_fitted: usize,
}

fn fit_points(points: &[(f64, f64)], held: Held) -> Result<FitResult, FitError> {
    let used: Vec<&(f64, f64)> = points.iter().filter(|(p, _)| *p > 0.0).collect();
    let p: Vec<f64> = used.iter().map(|x| x.0).collect();
    let phi: Vec<f64> = used.iter().map(|x| x.1).collect();
    let opt = FitOptions {
        fix_phi1: held.phi1,
        fix_phi2: held.phi2,
        ..FitOptions::default()
    };
    fit_eq13(&p, &phi, None, &opt)
}

/// Eq. 13 fitted to the runs' mean pressure at fixed φ over `grid` (points of positive mean
/// pressure), with the seed-to-seed error of each free parameter.
pub fn fit_ensemble(
    runs: &[&CurveTable],
    grid: &[f64],
    held: Held,
) -> Result<EnsembleFit, FitError> {
    let mean: Vec<(f64, f64)> = average_at_fixed_phi(runs, grid)
        .iter()
        .map(|a| (a.p_mean, a.phi))
        .collect();
    let mean_fit = fit_points(&mean, held)?;
    let per_seed: Vec<FitResult> = runs
        .iter()
        .filter_map(|r| {
            let own: Vec<(f64, f64)> = average_at_fixed_phi(&[*r], grid)
                .iter()
                .map(|a| (a.p_mean, a.phi))
                .collect();
            fit_points(&own, held).ok()
        })
        .collect();
    let n = per_seed.len();
    let all = n == runs.len() && n > 1;
    let t = student_t68(n.saturating_sub(1));
    let half_width = |values: Vec<f64>| match spread(&values) {
        Some(s) if all => t * s.sem,
        _ => f64::NAN,
    };
    let held_or = |held: Option<f64>, w: f64| if held.is_some() { 0.0 } else { w };
    let err_log10_pm = half_width(per_seed.iter().map(|f| f.params.p_m.log10()).collect());
    let err = Eq13 {
        phi1: held_or(
            held.phi1,
            half_width(per_seed.iter().map(|f| f.params.phi1).collect()),
        ),
        phi2: held_or(
            held.phi2,
            half_width(per_seed.iter().map(|f| f.params.phi2).collect()),
        ),
        p_m: mean_fit.params.p_m * std::f64::consts::LN_10 * err_log10_pm,
        delta: half_width(per_seed.iter().map(|f| f.params.delta).collect()),
    };
    Ok(EnsembleFit {
        mean_fit,
        err,
        err_log10_pm,
        seeds_fitted: n,
    })
}
