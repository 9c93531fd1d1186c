//! The speed laws of Seizinger et al. (2012), Eqs. 14–17, fitted to the per-speed p_m and Δ of
//! one model and size, each only where the data constrain it: a fit that did not converge,
//! whose errors are not finite, that sits on a parameter's bound or whose parameters have a
//! sign the law cannot have is reported as such, never as a value.

#[cfg(test)]
mod tests;

use super::speed_laws::{
    fit_power_law, fit_quadratic, fit_shifted_power_law, LawFit, PowerLaw, Quadratic,
    ShiftedPowerLaw,
};

/// A law's fit, or why there is none to report.
#[derive(Clone, Debug)]
pub enum Law<L> {
    Fitted(LawFit<L>),
    Unconstrained(String),
}

impl<L> Law<L> {
    pub fn fitted(&self) -> Option<&LawFit<L>> {
        match self {
            Law::Fitted(f) => Some(f),
            Law::Unconstrained(_) => None,
        }
    }
}

/// One speed's Eq. 13 result: v [m/s], p_m [kPa], its error, Δ, its error (errors NaN where
/// there is none).
pub type SpeedValue = [f64; 5];

/// The laws of one family.
#[derive(Clone, Debug)]
pub struct Laws {
    /// Eq. 15: p_m = a v^b + c [kPa], v ≥ 1 m/s.
    pub pm_dynamic: Law<PowerLaw>,
    /// Eq. 16: the same with b = 2.
    pub pm_square: Law<PowerLaw>,
    /// Eq. 17: Δ = (v + a)^b + c.
    pub delta: Law<ShiftedPowerLaw>,
    /// Eq. 14: p_m = a v² + b v + c [kPa], v ≤ 1 m/s.
    pub pm_slow: Law<Quadratic>,
    /// v_crit = −b/(2a) of Eq. 14 with its error, or why not.
    pub v_crit: Result<(f64, f64), String>,
}

fn column(p: &[SpeedValue], k: usize) -> Vec<f64> {
    p.iter().map(|x| x[k]).collect()
}

/// A law's three parameters, scaled together.
pub trait Scalable {
    fn scaled(&self, k: f64) -> Self;
}

macro_rules! scalable {
    ($($law:ty),*) => {$(
        impl Scalable for $law {
            fn scaled(&self, k: f64) -> Self {
                Self { a: k * self.a, b: k * self.b, c: k * self.c }
            }
        }
    )*};
}
scalable!(PowerLaw, Quadratic, ShiftedPowerLaw);

/// Seed errors say how well each speed's p_m or Δ is known, not how well the law describes
/// the speeds: a law that misses its points by more than their errors (χ²/dof > 1; 20 for
/// Eq. 15, 584 for Eq. 14 in the paper tier) has its errors multiplied by √(χ²/dof), the
/// Birge ratio, so that its coefficients claim no more precision than the scatter allows.
/// Unweighted fits already take their errors from the residuals.
fn scaled_by_scatter<L: Scalable>(
    fit: Result<LawFit<L>, String>,
    weighted: bool,
) -> Result<LawFit<L>, String> {
    fit.map(|mut f| {
        if weighted && f.chi2_per_dof > 1.0 {
            f.error_scale = f.chi2_per_dof.sqrt();
            f.std_err = f.std_err.scaled(f.error_scale);
        }
        f
    })
}

/// Seed errors where every speed has one, else none (the residual scatter scales them).
fn sigma(p: &[SpeedValue], k: usize) -> Option<Vec<f64>> {
    let s = column(p, k);
    s.iter().all(|e| e.is_finite() && *e > 0.0).then_some(s)
}

fn problem_of<L>(fit: &LawFit<L>, values: &[f64], errors: &[f64]) -> Option<String> {
    if !fit.converged {
        return Some("did not converge".into());
    }
    if errors.iter().any(|e| !e.is_finite()) || values.iter().any(|v| !v.is_finite()) {
        return Some("errors not finite: the speeds do not constrain it".into());
    }
    // A parameter known to no better than ten times its own size (or ten units, for one near
    // zero) is not measured: three parameters through four or five points can pass every
    // point with errors in the thousands.
    if let Some((v, e)) = values
        .iter()
        .zip(errors)
        .find(|(v, e)| **e > LOOSE * v.abs().max(1.0))
    {
        return Some(format!(
            "a parameter of {v:.3} ± {e:.3}: the speeds do not constrain it"
        ));
    }
    None
}

/// A standard error beyond this many times max(|value|, 1) leaves a parameter unmeasured.
const LOOSE: f64 = 10.0;

fn checked<L>(
    fit: Result<LawFit<L>, String>,
    params: impl Fn(&L) -> Vec<f64>,
    physical: impl Fn(&LawFit<L>) -> Option<String>,
) -> Law<L> {
    match fit {
        Err(e) => Law::Unconstrained(e),
        // A bound or a sign first: a fit stuck on a bound often fails to converge too, and
        // the bound says more.
        Ok(f) => {
            match physical(&f).or_else(|| problem_of(&f, &params(&f.law), &params(&f.std_err))) {
                Some(why) => Law::Unconstrained(why),
                None => Law::Fitted(f),
            }
        }
    }
}

/// Negative beyond two standard errors.
fn negative(v: f64, e: f64) -> bool {
    v + 2.0 * e < 0.0
}

fn power_law(p: &[SpeedValue], fixed_b: Option<f64>) -> Law<PowerLaw> {
    let need = if fixed_b.is_some() { 3 } else { 4 };
    if p.len() < need {
        return Law::Unconstrained(format!("{} speeds, at least {need} needed", p.len()));
    }
    let errors = sigma(p, 2);
    let fit = fit_power_law(&column(p, 0), &column(p, 1), errors.as_deref(), fixed_b)
        .map_err(|e| e.to_string());
    let fit = scaled_by_scatter(fit, errors.is_some());
    checked(
        fit,
        |l| vec![l.a, l.b, l.c],
        |f| {
            if negative(f.law.c, f.std_err.c) {
                Some(format!(
                    "unphysical: c = {:.3} ± {:.3} kPa < 0 (p_m below zero at small v)",
                    f.law.c, f.std_err.c
                ))
            } else if f.law.a <= 0.0 {
                Some(format!("unphysical: a = {:.3} ≤ 0", f.law.a))
            } else {
                None
            }
        },
    )
}

/// Whether Eq. 17's shift `a` sits on its bound a > −min v: v_min + a within a thousandth of
/// v_min (of 1 mm/s, for speeds below that), where (v + a)^b is a pole fitted to a point.
fn shift_on_bound(v_min: f64, a: f64) -> bool {
    v_min + a < 1e-3 * v_min.max(1e-3)
}

fn delta_law(p: &[SpeedValue]) -> Law<ShiftedPowerLaw> {
    if p.len() < 4 {
        return Law::Unconstrained(format!("{} speeds, at least 4 needed", p.len()));
    }
    let v = column(p, 0);
    let v_min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let errors = sigma(p, 4);
    let fit =
        fit_shifted_power_law(&v, &column(p, 3), errors.as_deref()).map_err(|e| e.to_string());
    let fit = scaled_by_scatter(fit, errors.is_some());
    checked(
        fit,
        |l| vec![l.a, l.b, l.c],
        |f| {
            if shift_on_bound(v_min, f.law.a) {
                Some(format!(
                    "on its bound: a = {:.5} at −min v = {:.5}",
                    f.law.a, -v_min
                ))
            } else if negative(f.law.c, f.std_err.c) {
                Some(format!(
                    "unphysical: c = {:.3} ± {:.3} < 0 (Δ below zero at high v)",
                    f.law.c, f.std_err.c
                ))
            } else {
                None
            }
        },
    )
}

fn quadratic(p: &[SpeedValue]) -> (Law<Quadratic>, Result<(f64, f64), String>) {
    if p.len() < 4 {
        let why = format!("{} speeds ≤ 1 m/s, at least 4 needed", p.len());
        return (Law::Unconstrained(why.clone()), Err(why));
    }
    let errors = sigma(p, 2);
    let fit =
        fit_quadratic(&column(p, 0), &column(p, 1), errors.as_deref()).map_err(|e| e.to_string());
    let fit = scaled_by_scatter(fit, errors.is_some());
    let law = checked(fit, |l| vec![l.a, l.b, l.c], |_| None);
    let v_crit = match &law {
        Law::Unconstrained(why) => Err(why.clone()),
        Law::Fitted(f) if f.law.a <= 0.0 => {
            Err(format!("p_m(v) has no minimum: a = {:.3} ≤ 0", f.law.a))
        }
        Law::Fitted(f) => {
            let (a, b) = (f.law.a, f.law.b);
            let v = -b / (2.0 * a);
            // Error propagation through −b/(2a), with the a–b correlation.
            let (sa, sb) = (f.std_err.a, f.std_err.b);
            let ia = f.free.iter().position(|n| *n == "a");
            let ib = f.free.iter().position(|n| *n == "b");
            let rho = match (ia, ib) {
                (Some(i), Some(j)) => f.correlation[i][j],
                _ => 0.0,
            };
            let (da, db) = (b / (2.0 * a * a), -1.0 / (2.0 * a));
            let var = (da * sa).powi(2) + (db * sb).powi(2) + 2.0 * rho * da * db * sa * sb;
            Ok((v, var.max(0.0).sqrt()))
        }
    };
    (law, v_crit)
}

/// The laws of one model and size from its speeds: Eqs. 15 and 16 from those ≥ 1 m/s, Eq. 14
/// and v_crit from those ≤ 1 m/s, Eq. 17 from all (its v → 0 limit is Güttler's Δ).
pub fn speed_laws(values: &[SpeedValue]) -> Laws {
    let keep = |f: fn(f64) -> bool| -> Vec<SpeedValue> {
        values.iter().copied().filter(|x| f(x[0])).collect()
    };
    let fast = keep(|v| v >= 1.0);
    let (pm_slow, v_crit) = quadratic(&keep(|v| v <= 1.0));
    Laws {
        pm_dynamic: power_law(&fast, None),
        pm_square: power_law(&fast, Some(2.0)),
        delta: delta_law(values),
        pm_slow,
        v_crit,
    }
}
