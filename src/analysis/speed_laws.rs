//! The wall-speed dependence of the Eq. 13 parameters (Sect. 5.2): the paper's ansätze
//! for p_m(v) and Δ(v), their least-squares fits to per-speed values, and the paper's own
//! fits as constants to print beside ours.
//!
//! The same machinery fits a straight line with errors ([`fit_line`]), which the
//! compaction-front speed uses.
//!
//! Speeds are in m/s. The laws are unit-agnostic in y; the paper's p_m constants are in kPa.

#[cfg(test)]
mod tests;

use super::fit::linalg::solve_spd;
use super::fit::lm::Problem;
use std::fmt;

/// p_m(v) = a v² + b v + c, the paper's ansatz for v ≤ 1 m/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadratic {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

/// y(v) = a v^b + c, the paper's ansatz for p_m at v ≥ 1 m/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

/// Δ(v) = (v + a)^b + c, the paper's ansatz for the transition width.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShiftedPowerLaw {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl Quadratic {
    pub fn eval(&self, v: f64) -> f64 {
        (self.a * v + self.b) * v + self.c
    }

    /// Where the parabola turns, −b/(2a).
    pub fn vertex(&self) -> f64 {
        -self.b / (2.0 * self.a)
    }
}

impl PowerLaw {
    pub fn eval(&self, v: f64) -> f64 {
        self.a * v.powf(self.b) + self.c
    }
}

impl ShiftedPowerLaw {
    pub fn eval(&self, v: f64) -> f64 {
        (v + self.a).powf(self.b) + self.c
    }
}

/// y(x) = a + b x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub a: f64,
    pub b: f64,
}

impl Line {
    pub fn eval(&self, x: f64) -> f64 {
        self.a + self.b * x
    }
}

/// The paper's p_m(v) [kPa] for v ≤ 1 m/s, Eq. 14.
pub const PAPER_PM_QUASI_STATIC: Quadratic = Quadratic {
    a: 18.296,
    b: -33.663,
    c: 16.667,
};
/// The paper's p_m(v) [kPa] for v ≥ 1 m/s, Eq. 15.
pub const PAPER_PM_DYNAMIC: PowerLaw = PowerLaw {
    a: 1.340,
    b: 1.93,
    c: 0.307,
};
/// The paper's p_m(v) [kPa] for v ≥ 1 m/s with the exponent fixed at 2, Eq. 16.
pub const PAPER_PM_DYNAMIC_SQUARE: PowerLaw = PowerLaw {
    a: 1.087,
    b: 2.0,
    c: 0.560,
};
/// The paper's Δ(v), Eq. 17.
pub const PAPER_DELTA: ShiftedPowerLaw = ShiftedPowerLaw {
    a: 1.598,
    b: -1.997,
    c: 0.170,
};
/// Speed [m/s] where p_m(v) stops falling and starts rising, as the paper states it.
pub const PAPER_V_CRIT: f64 = 0.9;

/// A fitted law with one-sigma errors (zero for a fixed parameter).
#[derive(Clone, Debug, PartialEq)]
pub struct LawFit<L> {
    pub law: L,
    pub std_err: L,
    /// Correlation matrix of the free parameters, ordered as `free`.
    pub correlation: Vec<Vec<f64>>,
    /// Free parameters, from "a", "b", "c".
    pub free: Vec<&'static str>,
    /// χ²/dof when σ was given; otherwise RSS/dof, the residual variance that scales the
    /// reported errors (as in [`super::fit::fit_eq13`]).
    pub chi2_per_dof: f64,
    pub dof: usize,
    /// Factor the σ-based errors were multiplied by for the scatter about the law
    /// (√(χ²/dof) where that exceeds 1, see `law_checks`); 1 as fitted.
    pub error_scale: f64,
    pub iterations: usize,
    pub converged: bool,
}

/// Why a law could not be fitted.
#[derive(Clone, Debug, PartialEq)]
pub enum LawError {
    LengthMismatch {
        expected: usize,
        found: usize,
    },
    /// A speed or value not finite, or a speed outside the law's domain.
    InvalidPoint {
        index: usize,
        v: f64,
        y: f64,
    },
    InvalidSigma {
        index: usize,
        sigma: f64,
    },
    TooFewPoints {
        points: usize,
        free: usize,
    },
    /// The data do not constrain all free parameters.
    Singular,
}

impl fmt::Display for LawError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LawError::LengthMismatch { expected, found } => {
                write!(f, "{found} values or errors for {expected} speeds")
            }
            LawError::InvalidPoint { index, v, y } => {
                write!(
                    f,
                    "point {index}: (v = {v} m/s, {y}) is not usable for this law"
                )
            }
            LawError::InvalidSigma { index, sigma } => write!(
                f,
                "point {index}: uncertainty {sigma} is not finite and positive"
            ),
            LawError::TooFewPoints { points, free } => write!(
                f,
                "{points} points cannot fit {free} free parameters with errors: need {}",
                free + 1
            ),
            LawError::Singular => write!(f, "the data do not constrain all free parameters"),
        }
    }
}

impl std::error::Error for LawError {}

const NAMES: [&str; 3] = ["a", "b", "c"];
const MAX_ITERATIONS: usize = 500;

/// Fitted θ = (a, b, c) with errors, before it is dressed as a law.
struct Solution {
    theta: [f64; 4],
    err: [f64; 4],
    fit: LawFit<()>,
}

/// Checks the points and returns the weights 1/σ² (ones without σ).
fn weights(
    v: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    domain: impl Fn(f64) -> bool,
) -> Result<Vec<f64>, LawError> {
    let n = v.len();
    for len in [y.len()].into_iter().chain(sigma.map(|s| s.len())) {
        if len != n {
            return Err(LawError::LengthMismatch {
                expected: n,
                found: len,
            });
        }
    }
    for (index, (&v, &y)) in v.iter().zip(y).enumerate() {
        if !(v.is_finite() && y.is_finite() && domain(v)) {
            return Err(LawError::InvalidPoint { index, v, y });
        }
    }
    match sigma {
        None => Ok(vec![1.0; n]),
        Some(s) => s
            .iter()
            .enumerate()
            .map(|(index, &sigma)| {
                let w = 1.0 / (sigma * sigma);
                if sigma.is_finite() && sigma > 0.0 && w.is_finite() {
                    Ok(w)
                } else {
                    Err(LawError::InvalidSigma { index, sigma })
                }
            })
            .collect(),
    }
}

/// Errors, correlations and χ² of the problem at its solution θ.
fn finish(
    d: &Problem,
    with_sigma: bool,
    theta: [f64; 4],
    idx: &[usize],
    iterations: usize,
    converged: bool,
) -> Result<Solution, LawError> {
    let k = idx.len();
    let cov = d.covariance(&theta, idx).ok_or(LawError::Singular)?;
    let dof = d.x.len() - k;
    let chi2_per_dof = if with_sigma {
        d.chi2(&theta)
    } else {
        d.rss(&theta)
    } / dof as f64;
    let scale = if with_sigma { 1.0 } else { chi2_per_dof };
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
    Ok(Solution {
        theta,
        err,
        fit: LawFit {
            law: (),
            std_err: (),
            correlation,
            free: idx.iter().map(|&j| NAMES[j]).collect(),
            chi2_per_dof,
            dof,
            error_scale: 1.0,
            iterations,
            converged,
        },
    })
}

/// Weighted least squares of a model linear in its free parameters `idx`: one exact
/// Gauss–Newton step from `theta` (whose fixed entries are kept).
fn solve_linear(d: &Problem, mut theta: [f64; 4], idx: &[usize]) -> Option<[f64; 4]> {
    let (a, g) = d.normal_equations(&theta, idx);
    let step = solve_spd(&a, &g, idx.len())?;
    for (s, &j) in step.iter().zip(idx) {
        theta[j] += s;
    }
    Some(theta)
}

fn too_few(n: usize, free: usize) -> Result<(), LawError> {
    if n < free + 1 {
        return Err(LawError::TooFewPoints { points: n, free });
    }
    Ok(())
}

fn dress<L>(s: Solution, make: impl Fn(&[f64; 4]) -> L) -> LawFit<L> {
    let f = s.fit;
    LawFit {
        law: make(&s.theta),
        std_err: make(&s.err),
        correlation: f.correlation,
        free: f.free,
        chi2_per_dof: f.chi2_per_dof,
        dof: f.dof,
        error_scale: f.error_scale,
        iterations: f.iterations,
        converged: f.converged,
    }
}

fn quadratic_model(t: &[f64; 4], v: f64) -> (f64, [f64; 4]) {
    ((t[0] * v + t[1]) * v + t[2], [v * v, v, 1.0, 0.0])
}

fn power_model(t: &[f64; 4], v: f64) -> (f64, [f64; 4]) {
    let vb = v.powf(t[1]);
    (t[0] * vb + t[2], [vb, t[0] * vb * v.ln(), 1.0, 0.0])
}

fn shifted_model(t: &[f64; 4], v: f64) -> (f64, [f64; 4]) {
    let u = v + t[0];
    let ub = u.powf(t[1]);
    (ub + t[2], [t[1] * ub / u, ub * u.ln(), 1.0, 0.0])
}

fn line_model(t: &[f64; 4], x: f64) -> (f64, [f64; 4]) {
    (t[0] + t[1] * x, [1.0, x, 0.0, 0.0])
}

fn always(_: &[f64; 4]) -> bool {
    true
}

/// Least-squares p_m(v) = a v² + b v + c (linear). `sigma`: one-sigma errors of `y`, or
/// `None` to take the residual scatter as the error.
pub fn fit_quadratic(
    v: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
) -> Result<LawFit<Quadratic>, LawError> {
    let w = weights(v, y, sigma, |_| true)?;
    too_few(v.len(), 3)?;
    let d = Problem {
        x: v,
        y,
        w: &w,
        model: &quadratic_model,
        admissible: &always,
    };
    let idx = [0, 1, 2];
    let theta = solve_linear(&d, [0.0; 4], &idx).ok_or(LawError::Singular)?;
    let s = finish(&d, sigma.is_some(), theta, &idx, 1, true)?;
    Ok(dress(s, |t| Quadratic {
        a: t[0],
        b: t[1],
        c: t[2],
    }))
}

/// Least-squares y(v) = a v^b + c for speeds v > 0: nonlinear in b when `fixed_b` is
/// `None`, linear in (a, c) with b held at `fixed_b` (the paper's second fit holds b = 2).
pub fn fit_power_law(
    v: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
    fixed_b: Option<f64>,
) -> Result<LawFit<PowerLaw>, LawError> {
    let w = weights(v, y, sigma, |v| v > 0.0)?;
    let d = Problem {
        x: v,
        y,
        w: &w,
        model: &power_model,
        admissible: &always,
    };
    let linear = [0, 2];
    let s = match fixed_b {
        Some(b) => {
            too_few(v.len(), 2)?;
            let theta = solve_linear(&d, [0.0, b, 0.0, 0.0], &linear).ok_or(LawError::Singular)?;
            finish(&d, sigma.is_some(), theta, &linear, 1, true)?
        }
        None => {
            too_few(v.len(), 3)?;
            // Start from the best (a, c) on a grid of exponents.
            let start = (0..=60)
                .filter_map(|i| solve_linear(&d, [0.0, 0.1 * i as f64 - 1.0, 0.0, 0.0], &linear))
                .min_by(|s, t| d.chi2(s).total_cmp(&d.chi2(t)))
                .ok_or(LawError::Singular)?;
            let idx = [0, 1, 2];
            let (theta, it, ok) = d.levenberg_marquardt(start, &idx, MAX_ITERATIONS);
            finish(&d, sigma.is_some(), theta, &idx, it, ok)?
        }
    };
    Ok(dress(s, |t| PowerLaw {
        a: t[0],
        b: t[1],
        c: t[2],
    }))
}

/// Least-squares Δ(v) = (v + a)^b + c (nonlinear); a stays above −min v.
pub fn fit_shifted_power_law(
    v: &[f64],
    y: &[f64],
    sigma: Option<&[f64]>,
) -> Result<LawFit<ShiftedPowerLaw>, LawError> {
    let w = weights(v, y, sigma, |_| true)?;
    too_few(v.len(), 3)?;
    let v_min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let admissible = move |t: &[f64; 4]| v_min + t[0] > 0.0;
    let d = Problem {
        x: v,
        y,
        w: &w,
        model: &shifted_model,
        admissible: &admissible,
    };
    // Start from the best c on a grid of shifts u₀ = v_min + a (0.01 to 100, log-spaced)
    // and exponents b (−5 to 5).
    let mut start = None;
    for i in 0..=20 {
        let a = 10f64.powf(-2.0 + 0.2 * i as f64) - v_min;
        for j in 0..=20 {
            let b = -5.0 + 0.5 * j as f64;
            let Some(theta) = solve_linear(&d, [a, b, 0.0, 0.0], &[2]) else {
                continue;
            };
            let c = d.chi2(&theta);
            if c.is_finite() && start.is_none_or(|(_, best)| c < best) {
                start = Some((theta, c));
            }
        }
    }
    let (start, _) = start.ok_or(LawError::Singular)?;
    let idx = [0, 1, 2];
    let (theta, it, ok) = d.levenberg_marquardt(start, &idx, MAX_ITERATIONS);
    let s = finish(&d, sigma.is_some(), theta, &idx, it, ok)?;
    Ok(dress(s, |t| ShiftedPowerLaw {
        a: t[0],
        b: t[1],
        c: t[2],
    }))
}

/// Least-squares straight line y = a + b x (linear), `sigma` as for [`fit_quadratic`].
pub fn fit_line(x: &[f64], y: &[f64], sigma: Option<&[f64]>) -> Result<LawFit<Line>, LawError> {
    let w = weights(x, y, sigma, |_| true)?;
    too_few(x.len(), 2)?;
    let d = Problem {
        x,
        y,
        w: &w,
        model: &line_model,
        admissible: &always,
    };
    let idx = [0, 1];
    let theta = solve_linear(&d, [0.0; 4], &idx).ok_or(LawError::Singular)?;
    let s = finish(&d, sigma.is_some(), theta, &idx, 1, true)?;
    Ok(dress(s, |t| Line { a: t[0], b: t[1] }))
}
