//! Test fixtures of the reproduction's analysis: a speed with nothing measured, and the
//! pieces a test fills in by hand.

use super::analysis::{Family, SpeedResult};
use crate::analysis::average::Spread;
use crate::analysis::ensemble::EnsembleFit;
use crate::analysis::fit::{Eq13, FitResult};

/// A value over `count` seeds with standard error `sem`.
pub fn over_seeds(mean: f64, sem: f64, count: usize) -> Spread {
    Spread {
        mean,
        sd: sem * (count as f64).sqrt(),
        sem,
        count,
    }
}

/// Speed `v` of `seeds` seeds, φ₀ = 0.15, nothing measured.
pub fn bare_speed(v: f64, seeds: usize) -> SpeedResult {
    SpeedResult {
        speed: v,
        seeds: (1..=seeds as u64).collect(),
        phi0: over_seeds(0.15, 0.0, seeds),
        mean_curve: Vec::new(),
        transient: None,
        fixed: None,
        phi1_free: None,
        first_passage: None,
        regimes: None,
        front_elapsed: None,
        front_robust: None,
        front_mass_balance: None,
        layer_phi: None,
        phi_at_mpa: None,
        wall_clock_s: 0.0,
    }
}

/// An Eq. 13 ensemble fit with φ₁ = 0.15, φ₂ = 0.58 held: p_m [Pa] and Δ, each with its
/// seed error.
pub fn fitted(p_m: f64, p_m_err: f64, delta: f64, delta_err: f64) -> EnsembleFit {
    let params = Eq13 {
        phi1: 0.15,
        phi2: 0.58,
        p_m,
        delta,
    };
    let err = Eq13 {
        phi1: 0.0,
        phi2: 0.0,
        p_m: p_m_err,
        delta: delta_err,
    };
    EnsembleFit {
        mean_fit: FitResult {
            params,
            std_err: err,
            std_err_log10_pm: 0.0,
            correlation: Vec::new(),
            free: vec!["log10_p_m", "delta"],
            rss: 0.0,
            chi2_per_dof: 1.0,
            dof: 1,
            iterations: 1,
            converged: true,
        },
        err,
        err_log10_pm: 0.0,
        seeds_fitted: 3,
    }
}

pub fn family(monomers: usize, speeds: Vec<SpeedResult>) -> Family {
    Family {
        variant: "modified".into(),
        monomers,
        speeds,
    }
}
