//! The measurements of one study from its stored cases, read the way Seizinger et al. (2012)
//! read theirs (Sects. 3–5):
//! - the seeds averaged at fixed φ (the paper's figures), and at first passage of a pressure
//!   beside it (what the calibration reads);
//! - Eq. 13 fitted per speed against the study's own reference (Güttler et al. 2009 for omni,
//!   Blum & Schräpler 2004 for uni): φ₁ and φ₂ held at the reference's values, and φ₁ free;
//!   errors seed to seed;
//! - the three regimes from each run in time order;
//! - the compaction front the paper's way (first deviation over elapsed time), a robust
//!   variant (slope of the 0.05-excess edge) and the mass balance of the dense layer;
//! - the speed laws (Eqs. 14–17), each only where the data constrain it.

use super::store::CaseRecord;
use super::StudyKind;
use crate::analysis::average::{average_on_log_grid, spread, Spread};
use crate::analysis::ensemble::{average_at_fixed_phi, fit_ensemble, phi_grid, EnsembleFit};
use crate::analysis::ensemble::{FixedPhiPoint, Held};
use crate::analysis::fit::{Eq13, FitResult};
use crate::analysis::front::{
    elapsed_front_speed, mass_balance_front, run_front_speed, FrontOptions,
};
use crate::analysis::per_speed::fit_fixed;
use crate::analysis::regimes::{regimes_of_runs, RegimeOptions, RegimeSummary};
use crate::analysis::run_files::CurveTable;
use crate::analysis::transient::{impact_transient, Transient};
use crate::job::figure::{BLUM_SCHRAEPLER_2004_UNI, GUETTLER_2009_OMNI};
use std::collections::BTreeMap;

/// An excess over the initial slab this large is a deviation: slabs below the front have
/// not moved at all (their excess is zero to rounding), while one diameter thick slabs of a
/// 60 µm box scatter by σ_φ ≈ 0.005 between samples, so 0.01 also ignores stray monomers.
pub const DEVIATION: f64 = 0.01;
/// Spacing of the fixed-φ grid.
const PHI_STEP: f64 = 0.005;

/// The reference curve a study is compared with.
pub fn reference(kind: StudyKind) -> (&'static str, Eq13) {
    match kind {
        StudyKind::Uni => ("Blum & Schräpler (2004)", BLUM_SCHRAEPLER_2004_UNI),
        _ => ("Güttler et al. (2009)", GUETTLER_2009_OMNI),
    }
}

/// Everything measured at one (model, size, speed).
#[derive(Clone, Debug)]
pub struct SpeedResult {
    pub speed: f64,
    pub seeds: Vec<u64>,
    /// Starting filling factor (the first row) over the seeds.
    pub phi0: Spread,
    pub mean_curve: Vec<FixedPhiPoint>,
    /// The impact transient left out of the Eq. 13 fits (dynamic runs at v ≥ 1 m/s).
    pub transient: Option<Transient>,
    /// φ₁, φ₂ held at the reference's values.
    pub fixed: Option<EnsembleFit>,
    /// φ₁ free, φ₂ held.
    pub phi1_free: Option<EnsembleFit>,
    /// φ₁, φ₂ held, fitted to the first-passage average (errors: χ²-scaled residuals).
    pub first_passage: Option<FitResult>,
    pub regimes: Option<RegimeSummary>,
    /// Per-run front speeds over the seeds [m/s].
    pub front_elapsed: Option<Spread>,
    pub front_robust: Option<Spread>,
    pub front_mass_balance: Option<Spread>,
    pub layer_phi: Option<Spread>,
    /// φ where each run first reaches 1 MPa (rows in time order, log P between rows), over
    /// the seeds: the quasi-static runs stop there, beyond the fixed-φ grid's last point.
    pub phi_at_mpa: Option<Spread>,
    pub wall_clock_s: f64,
}

/// One model at one sample size.
#[derive(Clone, Debug)]
pub struct Family {
    pub variant: String,
    pub monomers: usize,
    pub speeds: Vec<SpeedResult>,
}

fn rows(c: &CurveTable) -> Vec<(f64, f64)> {
    c.p_top_pa
        .iter()
        .zip(&c.phi)
        .filter(|(p, _)| p.is_finite() && **p > 0.0)
        .map(|(&p, &phi)| (p, phi))
        .collect()
}

fn over_runs(runs: &[&CaseRecord], f: impl Fn(&CaseRecord) -> Option<f64>) -> Option<Spread> {
    let values: Vec<f64> = runs.iter().filter_map(|r| f(r)).collect();
    spread(&values)
}

fn fronts(runs: &[&CaseRecord], speed: f64) -> [Option<Spread>; 4] {
    let robust = FrontOptions::default();
    let balance = |r: &CaseRecord| mass_balance_front(&r.profiles, &robust, speed);
    [
        over_runs(runs, |r| {
            elapsed_front_speed(&r.profiles, DEVIATION).map(|f| f.v)
        }),
        over_runs(runs, |r| {
            run_front_speed(&r.profiles, &robust).map(|f| f.front.v)
        }),
        over_runs(runs, |r| balance(r).map(|b| b.1)),
        over_runs(runs, |r| balance(r).map(|b| b.0)),
    ]
}

fn speed_result(kind: StudyKind, runs: Vec<&CaseRecord>) -> SpeedResult {
    let (_, refc) = reference(kind);
    let speed = runs[0].entry.wall_speed_m_s;
    let curves: Vec<&CurveTable> = runs.iter().map(|r| &r.curve).collect();
    let grid = phi_grid(0.16, 0.7, PHI_STEP);
    let both = Held {
        phi1: Some(refc.phi1),
        phi2: Some(refc.phi2),
    };
    let phi1_free = Held { phi1: None, ..both };
    let run_rows: Vec<Vec<(f64, f64)>> = curves.iter().map(|c| rows(c)).collect();
    let passage = average_on_log_grid(&run_rows, 8);
    let passage: Vec<(f64, f64)> = passage.iter().map(|a| (a.p, a.mean)).collect();
    let dynamic = kind == StudyKind::Dynamic && speed >= 1.0;
    let mean_curve = average_at_fixed_phi(&curves, &grid);
    let transient = dynamic.then(|| impact_transient(&mean_curve)).flatten();
    // Eq. 13 is fitted from the end of the transient on; the mean curve keeps every point.
    let fit_grid = transient.map_or_else(|| grid.clone(), |t| phi_grid(t.phi_from, 0.7, PHI_STEP));
    let [front_elapsed, front_robust, front_mass_balance, layer_phi] = if dynamic {
        fronts(&runs, speed)
    } else {
        [None; 4]
    };
    let phi0: Vec<f64> = curves
        .iter()
        .filter_map(|c| c.phi.first().copied())
        .collect();
    SpeedResult {
        speed,
        seeds: runs.iter().map(|r| r.entry.seed).collect(),
        phi0: spread(&phi0).expect("a group has a run"),
        mean_curve,
        transient,
        fixed: fit_ensemble(&curves, &fit_grid, both).ok(),
        phi1_free: fit_ensemble(&curves, &fit_grid, phi1_free).ok(),
        first_passage: fit_fixed(&passage, None, refc.phi1, refc.phi2).ok(),
        regimes: dynamic.then(|| {
            // Every row, the start's too: regime (i)'s φ rise counts from there.
            let all: Vec<Vec<(f64, f64)>> = curves
                .iter()
                .map(|c| {
                    c.p_top_pa
                        .iter()
                        .copied()
                        .zip(c.phi.iter().copied())
                        .collect()
                })
                .collect();
            let r: Vec<&[(f64, f64)]> = all.iter().map(|r| r.as_slice()).collect();
            regimes_of_runs(&r, &RegimeOptions::default())
        }),
        front_elapsed,
        front_robust,
        front_mass_balance,
        layer_phi,
        phi_at_mpa: spread(
            &run_rows
                .iter()
                .filter_map(|r| first_passage_phi(r, 1e6))
                .collect::<Vec<_>>(),
        ),
        wall_clock_s: runs.iter().map(|r| r.entry.wall_clock_s).sum(),
    }
}

/// The study's cases grouped by (model, size), speeds ascending; models in `order` first.
pub fn analyse(kind: StudyKind, cases: &[CaseRecord], order: &[&str]) -> Vec<Family> {
    let mut groups: BTreeMap<(usize, String, usize), BTreeMap<u64, Vec<&CaseRecord>>> =
        BTreeMap::new();
    for c in cases {
        let rank = order
            .iter()
            .position(|v| *v == c.entry.variant)
            .unwrap_or(order.len());
        groups
            .entry((rank, c.entry.variant.clone(), c.entry.monomers))
            .or_default()
            .entry(c.entry.wall_speed_m_s.to_bits())
            .or_default()
            .push(c);
    }
    groups
        .into_iter()
        .map(|((_, variant, monomers), by_speed)| {
            let mut speeds: Vec<SpeedResult> = by_speed
                .into_values()
                .map(|mut runs| {
                    runs.sort_by_key(|r| r.entry.seed);
                    speed_result(kind, runs)
                })
                .collect();
            speeds.sort_by(|a, b| a.speed.total_cmp(&b.speed));
            Family {
                variant,
                monomers,
                speeds,
            }
        })
        .collect()
}

/// φ where a fixed-φ mean curve first reaches pressure `p` (linear in log P between grid
/// points); `None` if it never does or starts above it.
pub fn phi_at_pressure(curve: &[FixedPhiPoint], p: f64) -> Option<f64> {
    let k = curve.iter().position(|a| a.p_mean >= p)?;
    if k == 0 {
        return None;
    }
    let (lo, hi) = (&curve[k - 1], &curve[k]);
    if lo.p_mean <= 0.0 {
        return Some(hi.phi);
    }
    let t = (p.log10() - lo.p_mean.log10()) / (hi.p_mean.log10() - lo.p_mean.log10());
    Some(lo.phi + t * (hi.phi - lo.phi))
}

/// φ where rows (P, φ) in time order first reach pressure `p`, linear in log P between the
/// row before and the row that reaches it; `None` if no row does, or the first row does.
pub fn first_passage_phi(rows: &[(f64, f64)], p: f64) -> Option<f64> {
    let k = rows.iter().position(|r| r.0 >= p)?;
    let (lo, hi) = (rows.get(k.checked_sub(1)?)?, rows[k]);
    let t = (p.log10() - lo.0.log10()) / (hi.0.log10() - lo.0.log10());
    Some(lo.1 + t * (hi.1 - lo.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_passage_of_a_pressure_is_read_in_log_pressure_between_rows() {
        let rows = [(1e5, 0.50), (1e4, 0.49), (1e5, 0.51), (1e7, 0.53)];
        // 1 MPa is half-way from 1e5 to 1e7 in log P: φ half-way from 0.51 to 0.53.
        assert!((first_passage_phi(&rows, 1e6).unwrap() - 0.52).abs() < 1e-12);
        assert_eq!(first_passage_phi(&rows, 1e8), None);
        assert_eq!(first_passage_phi(&rows, 1e5), None);
    }
}
