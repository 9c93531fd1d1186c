//! Least-squares fit of the compressive-strength curve of porous
//! aggregates, Eq. 13 of Seizinger, Speith & Kley (2012):
//!
//! ```text
//! φ(P) = φ₂ − (φ₂ − φ₁) / (exp((log₁₀P − log₁₀p_m)/Δ) + 1)
//! ```
//!
//! The curve is a logistic in log₁₀P, so the fit runs in log₁₀p_m rather than
//! p_m: the problem is much better conditioned there and the error of
//! log₁₀p_m is close to Gaussian. The error of p_m itself follows by the delta
//! method and is only meaningful while it is small compared with p_m.

#[cfg(test)]
mod guard_tests;
pub(in crate::analysis) mod linalg;
pub(in crate::analysis) mod lm;
#[cfg(test)]
mod tests;

use lm::Problem;
use std::error::Error;
use std::fmt;

/// Parameters of Eq. 13: low- and high-pressure filling factors φ₁ and φ₂,
/// the pressure p_m [Pa] at the midpoint of the transition and its width Δ
/// in decades of pressure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eq13 {
    pub phi1: f64,
    pub phi2: f64,
    pub p_m: f64,
    pub delta: f64,
}

impl Eq13 {
    /// Filling factor at pressure `p` [Pa]. `p = 0` gives the limit φ₁,
    /// negative `p` gives NaN.
    pub fn phi(&self, p: f64) -> f64 {
        let s = lower_weight((p.log10() - self.p_m.log10()) / self.delta);
        // Blended form: exact at both plateaus.
        self.phi1 * s + self.phi2 * (1.0 - s)
    }

    /// Pressure [Pa] at which the curve reaches `phi`. `None` unless `phi`
    /// lies strictly between φ₁ and φ₂, which the curve only approaches
    /// asymptotically, or if the parameters do not describe a transition.
    pub fn pressure_at(&self, phi: f64) -> Option<f64> {
        let span = self.phi2 - self.phi1;
        let transition = span != 0.0 && span.is_finite() && self.delta > 0.0 && self.p_m > 0.0;
        if !transition {
            return None;
        }
        let s = (self.phi2 - phi) / span;
        if !(s > 0.0 && s < 1.0) {
            return None;
        }
        let log10_p = self.p_m.log10() + self.delta * ((1.0 - s) / s).ln();
        let p = 10f64.powf(log10_p);
        (p.is_finite() && p > 0.0).then_some(p)
    }
}

/// Control of [`fit_eq13`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Hold φ₁ at this value instead of fitting it.
    pub fix_phi1: Option<f64>,
    /// Hold φ₂ at this value instead of fitting it.
    pub fix_phi2: Option<f64>,
    /// Starting point; `None` searches a grid in (log₁₀p_m, Δ). Fixed φ
    /// values take precedence over the ones given here.
    pub initial: Option<Eq13>,
    pub max_iterations: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            fix_phi1: None,
            fix_phi2: None,
            initial: None,
            max_iterations: 200,
        }
    }
}

/// Outcome of [`fit_eq13`].
#[derive(Clone, Debug, PartialEq)]
pub struct FitResult {
    pub params: Eq13,
    /// One-sigma errors, zero for fixed parameters. The p_m entry is the
    /// delta-method error p_m·ln10·σ(log₁₀p_m).
    pub std_err: Eq13,
    pub std_err_log10_pm: f64,
    /// Correlation matrix of the free parameters, ordered as `free`.
    pub correlation: Vec<Vec<f64>>,
    /// Free parameters, from "phi1", "phi2", "log10_p_m", "delta".
    pub free: Vec<&'static str>,
    /// Unweighted residual sum of squares Σ(φᵢ − φ(Pᵢ))².
    pub rss: f64,
    /// χ²/dof when σ was given; otherwise s² = RSS/dof, the residual
    /// variance that scales the reported errors.
    pub chi2_per_dof: f64,
    pub dof: usize,
    pub iterations: usize,
    /// False if `max_iterations` ran out; `params` is then the best point
    /// reached and the errors are evaluated there.
    pub converged: bool,
}

/// Why [`fit_eq13`] could not produce a fit.
#[derive(Clone, Debug, PartialEq)]
pub enum FitError {
    /// `phi` or `sigma` is not as long as the pressure array.
    LengthMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
    },
    /// Pressure not finite and positive, or φ not finite.
    InvalidPoint {
        index: usize,
        pressure: f64,
        phi: f64,
    },
    /// Uncertainty not finite and positive.
    InvalidSigma { index: usize, sigma: f64 },
    /// A fixed or initial parameter outside its domain.
    InvalidOption { name: &'static str, value: f64 },
    /// Need at least one point more than free parameters to estimate errors.
    TooFewPoints { points: usize, free: usize },
    /// The data do not constrain all free parameters at the solution.
    Singular,
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FitError::LengthMismatch {
                what,
                expected,
                found,
            } => write!(
                f,
                "{what} has {found} entries but there are {expected} pressures"
            ),
            FitError::InvalidPoint {
                index,
                pressure,
                phi,
            } => {
                if pressure.is_finite() && pressure > 0.0 {
                    write!(f, "point {index}: filling factor {phi} is not finite")
                } else {
                    write!(
                        f,
                        "point {index}: pressure {pressure} Pa is not finite and positive"
                    )
                }
            }
            FitError::InvalidSigma { index, sigma } => write!(
                f,
                "point {index}: uncertainty {sigma} is not finite and positive"
            ),
            FitError::InvalidOption { name, value } => {
                write!(f, "option {name} = {value} is outside its domain")
            }
            FitError::TooFewPoints { points, free } => write!(
                f,
                "{points} points cannot fit {free} free parameters with error estimates: need at least {}",
                free + 1
            ),
            FitError::Singular => write!(
                f,
                "the data do not constrain all free parameters \
                 (is the transition inside the pressure range?)"
            ),
        }
    }
}

impl Error for FitError {}

const PHI1: usize = 0;
const PHI2: usize = 1;
const LOG_PM: usize = 2;
const DELTA: usize = 3;
const NAMES: [&str; 4] = ["phi1", "phi2", "log10_p_m", "delta"];

/// Fits Eq. 13 to filling factors `phi` measured at pressures `p` [Pa],
/// optionally weighted by one-sigma uncertainties `sigma` of φ.
///
/// Without `sigma` the errors are scaled by the residual variance, i.e. the
/// scatter of the data is taken as their uncertainty.
pub fn fit_eq13(
    p: &[f64],
    phi: &[f64],
    sigma: Option<&[f64]>,
    opt: &FitOptions,
) -> Result<FitResult, FitError> {
    let n = p.len();
    if phi.len() != n {
        return Err(FitError::LengthMismatch {
            what: "phi",
            expected: n,
            found: phi.len(),
        });
    }
    for (index, (&pressure, &phi)) in p.iter().zip(phi).enumerate() {
        if !(pressure.is_finite() && pressure > 0.0 && phi.is_finite()) {
            return Err(FitError::InvalidPoint {
                index,
                pressure,
                phi,
            });
        }
    }
    let w: Vec<f64> = match sigma {
        None => vec![1.0; n],
        Some(s) => {
            if s.len() != n {
                return Err(FitError::LengthMismatch {
                    what: "sigma",
                    expected: n,
                    found: s.len(),
                });
            }
            let mut w = Vec::with_capacity(n);
            for (index, &sigma) in s.iter().enumerate() {
                let wi = 1.0 / (sigma * sigma);
                if !(sigma.is_finite() && sigma > 0.0 && wi.is_finite()) {
                    return Err(FitError::InvalidSigma { index, sigma });
                }
                w.push(wi);
            }
            w
        }
    };
    check_options(opt)?;

    let free = [opt.fix_phi1.is_none(), opt.fix_phi2.is_none(), true, true];
    let idx: Vec<usize> = (0..4).filter(|&j| free[j]).collect();
    let k = idx.len();
    if n < k + 1 {
        return Err(FitError::TooFewPoints { points: n, free: k });
    }

    let x: Vec<f64> = p.iter().map(|v| v.log10()).collect();
    let data = Problem {
        x: &x,
        y: phi,
        w: &w,
        model: &model,
        // (Δ, φ₁, φ₂) and (−Δ, φ₂, φ₁) describe the same curve: Δ is kept positive.
        admissible: &|t| t[DELTA] > 0.0,
    };
    let mut theta = match opt.initial {
        Some(e) => [e.phi1, e.phi2, e.p_m.log10(), e.delta],
        None => initial_guess(&data, opt.fix_phi1, opt.fix_phi2),
    };
    if let Some(v) = opt.fix_phi1 {
        theta[PHI1] = v;
    }
    if let Some(v) = opt.fix_phi2 {
        theta[PHI2] = v;
    }

    let (theta, iterations, converged) = data.levenberg_marquardt(theta, &idx, opt.max_iterations);

    let cov = data.covariance(&theta, &idx).ok_or(FitError::Singular)?;
    let chi2 = data.chi2(&theta);
    let rss = data.rss(&theta);
    let dof = n - k;
    let chi2_per_dof = if sigma.is_some() { chi2 } else { rss } / dof as f64;
    let scale = if sigma.is_some() { 1.0 } else { chi2_per_dof };

    let mut err = [0.0; 4];
    for (a, &j) in idx.iter().enumerate() {
        err[j] = (scale * cov[a][a]).sqrt();
    }
    let correlation = (0..k)
        .map(|a| {
            (0..k)
                .map(|b| cov[a][b] / (cov[a][a] * cov[b][b]).sqrt())
                .collect()
        })
        .collect();
    let p_m = 10f64.powf(theta[LOG_PM]);
    Ok(FitResult {
        params: Eq13 {
            phi1: theta[PHI1],
            phi2: theta[PHI2],
            p_m,
            delta: theta[DELTA],
        },
        std_err: Eq13 {
            phi1: err[PHI1],
            phi2: err[PHI2],
            p_m: p_m * std::f64::consts::LN_10 * err[LOG_PM],
            delta: err[DELTA],
        },
        std_err_log10_pm: err[LOG_PM],
        correlation,
        free: idx.iter().map(|&j| NAMES[j]).collect(),
        rss,
        chi2_per_dof,
        dof,
        iterations,
        converged,
    })
}

fn check_options(opt: &FitOptions) -> Result<(), FitError> {
    let bad = |name, value| Err(FitError::InvalidOption { name, value });
    for (name, value) in [("fix_phi1", opt.fix_phi1), ("fix_phi2", opt.fix_phi2)] {
        if let Some(v) = value.filter(|v| !v.is_finite()) {
            return bad(name, v);
        }
    }
    if let Some(e) = opt.initial {
        if !e.phi1.is_finite() {
            return bad("initial.phi1", e.phi1);
        }
        if !e.phi2.is_finite() {
            return bad("initial.phi2", e.phi2);
        }
        if !(e.p_m.is_finite() && e.p_m > 0.0) {
            return bad("initial.p_m", e.p_m);
        }
        if !(e.delta.is_finite() && e.delta > 0.0) {
            return bad("initial.delta", e.delta);
        }
    }
    Ok(())
}

/// 1/(exp(u) + 1), the weight of φ₁ in Eq. 13, without overflow at large |u|.
fn lower_weight(u: f64) -> f64 {
    if u > 0.0 {
        let e = (-u).exp();
        e / (1.0 + e)
    } else {
        1.0 / (1.0 + u.exp())
    }
}

/// φ and its gradient in θ = (φ₁, φ₂, log₁₀p_m, Δ) at x = log₁₀P.
fn model(theta: &[f64; 4], x: f64) -> (f64, [f64; 4]) {
    let [phi1, phi2, log_pm, delta] = *theta;
    let u = (x - log_pm) / delta;
    let s = lower_weight(u);
    let span = phi2 - phi1;
    // ∂φ/∂u = (φ₂ − φ₁)·s·(1 − s), and ∂u/∂log₁₀p_m = −1/Δ, ∂u/∂Δ = −u/Δ.
    let dphi_du = span * s * (1.0 - s);
    (
        phi1 * s + phi2 * (1.0 - s),
        [s, 1.0 - s, -dphi_du / delta, -dphi_du * u / delta],
    )
}

/// Starting point from a grid in (log₁₀p_m, Δ). For given (p_m, Δ) the model
/// is linear in φ₁ and φ₂, so each grid node gets its best plateaus by linear
/// least squares; this finds the basin of the minimum without any knowledge
/// of the data's scale. The midpoint-crossing estimate is kept as a candidate
/// for data that constrain the plateaus too weakly for the grid.
fn initial_guess(d: &Problem, fix1: Option<f64>, fix2: Option<f64>) -> [f64; 4] {
    let (xmin, xmax) =
        d.x.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
    let mut best = midpoint_guess(d, fix1, fix2);
    let mut best_chi2 = d.chi2(&best);
    const NL: usize = 61;
    const ND: usize = 20;
    for i in 0..NL {
        let log_pm = xmin - 0.5 + (xmax - xmin + 1.0) * i as f64 / (NL - 1) as f64;
        for j in 0..ND {
            // Δ from 0.03 to 3 decades.
            let delta = 0.03 * 100f64.powf(j as f64 / (ND - 1) as f64);
            let Some((phi1, phi2)) = best_plateaus(d, log_pm, delta, fix1, fix2) else {
                continue;
            };
            let theta = [phi1, phi2, log_pm, delta];
            let c = d.chi2(&theta);
            if c < best_chi2 {
                best = theta;
                best_chi2 = c;
            }
        }
    }
    best
}

/// Weighted linear least squares for the free plateaus at fixed (p_m, Δ),
/// with φ = φ₁·s + φ₂·(1 − s).
fn best_plateaus(
    d: &Problem,
    log_pm: f64,
    delta: f64,
    fix1: Option<f64>,
    fix2: Option<f64>,
) -> Option<(f64, f64)> {
    let (mut ss, mut st, mut tt, mut sy, mut ty) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ((&x, &y), &w) in d.x.iter().zip(d.y).zip(d.w) {
        let s = lower_weight((x - log_pm) / delta);
        let t = 1.0 - s;
        let y = y - fix1.map_or(0.0, |v| v * s) - fix2.map_or(0.0, |v| v * t);
        ss += w * s * s;
        st += w * s * t;
        tt += w * t * t;
        sy += w * s * y;
        ty += w * t * y;
    }
    let tiny = 1e-9 * d.w.iter().sum::<f64>();
    let (phi1, phi2) = match (fix1, fix2) {
        (Some(a), Some(b)) => (a, b),
        (Some(a), None) => (a, (tt > tiny).then(|| ty / tt)?),
        (None, Some(b)) => ((ss > tiny).then(|| sy / ss)?, b),
        (None, None) => {
            let det = ss * tt - st * st;
            if !(det > 1e-6 * ss * tt && ss > tiny && tt > tiny) {
                return None;
            }
            ((tt * sy - st * ty) / det, (ss * ty - st * sy) / det)
        }
    };
    (phi1.is_finite() && phi2.is_finite()).then_some((phi1, phi2))
}

/// Plateaus at the data extremes, p_m where φ crosses their mean, Δ = 0.5.
fn midpoint_guess(d: &Problem, fix1: Option<f64>, fix2: Option<f64>) -> [f64; 4] {
    let mut pts: Vec<(f64, f64)> = d.x.iter().copied().zip(d.y.iter().copied()).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ymin = pts.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let ymax = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let phi1 = fix1.unwrap_or(ymin);
    let phi2 = fix2.unwrap_or(ymax);
    let mid = 0.5 * (phi1 + phi2);
    let crossing = pts.windows(2).find_map(|w| {
        let (a, b) = (w[0], w[1]);
        ((a.1 - mid) * (b.1 - mid) <= 0.0 && a.1 != b.1)
            .then(|| a.0 + (b.0 - a.0) * (mid - a.1) / (b.1 - a.1))
    });
    let log_pm = crossing.unwrap_or_else(|| {
        pts.iter()
            .min_by(|a, b| (a.1 - mid).abs().total_cmp(&(b.1 - mid).abs()))
            .map_or(0.0, |p| p.0)
    });
    [phi1, phi2, log_pm, 0.5]
}
