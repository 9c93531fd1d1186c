//! Averaging of φ–P curves over sample seeds on a common log-spaced pressure grid.
//!
//! A curve is read at a pressure the way the calibration reads it
//! ([`Envelope::phi_at`]): log₁₀P is smoothed by a running median over a few rows and
//! replaced by its running maximum, and φ at P is the filling factor when the sample *first*
//! held P, interpolated linearly in log₁₀P between the rows around that crossing. A curve
//! whose pressure drops back (a jammed contact chain letting go, the compacted layer hitting
//! the bottom) thus gives one φ per pressure, the earliest; a curve never reaching P does not
//! count at P. Below a curve's first pressure its starting φ is used.

#[cfg(test)]
mod tests;

use super::envelope::Envelope;

/// One grid pressure of an average.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AveragePoint {
    /// Grid pressure [Pa].
    pub p: f64,
    /// Mean φ over the curves that reach `p`.
    pub mean: f64,
    /// Seed-to-seed standard deviation (n − 1 in the denominator); NaN for one curve.
    pub sd: f64,
    /// Standard error of the mean, sd/√count; NaN for one curve.
    pub sem: f64,
    /// Number of curves that reach `p`.
    pub count: usize,
}

/// Mean and seed-to-seed spread of one quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    pub mean: f64,
    /// Sample standard deviation (n − 1 in the denominator); NaN for one value.
    pub sd: f64,
    /// Standard error of the mean, sd/√count; NaN for one value.
    pub sem: f64,
    pub count: usize,
}

/// Mean, standard deviation and standard error of `values`; `None` when empty.
pub fn spread(values: &[f64]) -> Option<Spread> {
    let count = values.len();
    if count == 0 {
        return None;
    }
    let n = count as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = if count > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        f64::NAN
    };
    Some(Spread {
        mean,
        sd,
        sem: sd / n.sqrt(),
        count,
    })
}

/// Pressures from `lo` to `hi` [Pa] (both included, `lo < hi`, both positive) spaced evenly in
/// log₁₀P with `per_decade` points per decade (at least two points).
pub fn log_grid(lo: f64, hi: f64, per_decade: usize) -> Vec<f64> {
    assert!(
        lo > 0.0 && hi > lo && hi.is_finite() && per_decade > 0,
        "log_grid needs 0 < lo < hi finite and per_decade > 0, got {lo}, {hi}, {per_decade}"
    );
    let (a, b) = (lo.log10(), hi.log10());
    let n = (((b - a) * per_decade as f64).ceil() as usize).max(1) + 1;
    (0..n)
        .map(|i| 10f64.powf(a + (b - a) * i as f64 / (n - 1) as f64))
        .collect()
}

/// φ of `curve` (points (P [Pa], φ) in time order) when the sample first held `p`, read as
/// the calibration reads it (see the module doc); NaN if it never did.
pub fn phi_at(curve: &[(f64, f64)], p: f64) -> f64 {
    envelope(curve).phi_at(p)
}

fn envelope(curve: &[(f64, f64)]) -> Envelope {
    let rows: Vec<(f64, f64)> = curve.iter().map(|&(p, phi)| (phi, p)).collect();
    Envelope::from_rows(&rows)
}

/// Mean, spread and count of the curves' φ at each pressure of `grid`; grid pressures that
/// no curve reaches are left out. Each curve is (P [Pa], φ) in time order.
pub fn average_curves(curves: &[Vec<(f64, f64)>], grid: &[f64]) -> Vec<AveragePoint> {
    let envelopes: Vec<Envelope> = curves
        .iter()
        .filter(|c| !c.is_empty())
        .map(|c| envelope(c))
        .collect();
    grid.iter()
        .filter_map(|&p| {
            let values: Vec<f64> = envelopes
                .iter()
                .map(|e| e.phi_at(p))
                .filter(|v| v.is_finite())
                .collect();
            let s = spread(&values)?;
            Some(AveragePoint {
                p,
                mean: s.mean,
                sd: s.sd,
                sem: s.sem,
                count: s.count,
            })
        })
        .collect()
}

/// [`average_curves`] on a [`log_grid`] with `per_decade` points per decade from the lowest
/// positive to the highest pressure of any curve.
pub fn average_on_log_grid(curves: &[Vec<(f64, f64)>], per_decade: usize) -> Vec<AveragePoint> {
    let (lo, hi) = curves
        .iter()
        .flatten()
        .map(|&(p, _)| p)
        .filter(|p| p.is_finite() && *p > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    if hi <= lo {
        return Vec::new();
    }
    average_curves(curves, &log_grid(lo, hi, per_decade))
}
