//! Leave one curve out: each effect's fit repeated without each curve in turn, and whether
//! it predicts the curve it was not fitted to.

use super::attribution::PREDICTION_LIMIT;
use super::gap::{chi2_quantile_95, gap};
use super::grid::{minimum_of, Grid};
use super::measured::MeasuredSet;

/// A curve left out of a fit and predicted by it.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOut {
    pub curve: String,
    /// The factor fitted to the other curves.
    pub factor: f64,
    /// The factors the other curves allow (their χ² within 3.84 of its minimum: 95% for one
    /// parameter).
    pub allowed: (f64, f64),
    /// The left-out curve's lowest χ² over the allowed factors: the refit's own uncertainty
    /// counts, so weak constraints from the other curves are not read as a failed prediction.
    pub chi2: f64,
    /// The other curves pin the factor: their χ² varies by more than 1 over the searched
    /// range. Where they do not (side walls against a uni curve and a sticking velocity,
    /// which no side wall touches), the left-out curve cannot be predicted from them and is
    /// not judged.
    pub constrained: bool,
    /// Within [`PREDICTION_LIMIT`] (always true where not constrained).
    pub predicted: bool,
}

/// Leave-one-curve-out: the grid fitted to every curve but one, for each curve in turn, and
/// the left-out curve's χ² over the factors that fit allows. Empty for a single curve.
pub fn held_out(m: &MeasuredSet, grid: &Grid) -> Vec<HeldOut> {
    let names: Vec<String> = gap(m, &grid.points[0].1)
        .curves
        .into_iter()
        .map(|c| c.name)
        .collect();
    if names.len() < 2 {
        return Vec::new();
    }
    let allowed_rise = chi2_quantile_95(1);
    names
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let scan = grid.scan_curves(m, &|k| k != j);
            let (u, best, _) = minimum_of(&scan);
            let spread = scan.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max) - best;
            let constrained = spread > 1.0;
            let allowed: Vec<f64> = scan
                .iter()
                .filter(|(_, c)| *c <= best + allowed_rise)
                .map(|(u, _)| *u)
                .collect();
            let chi2 = allowed
                .iter()
                .map(|&v| gap(m, &grid.interpolate(v)).curves[j].chi2)
                .fold(f64::INFINITY, f64::min);
            let lo = allowed.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = allowed.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            HeldOut {
                curve: name.clone(),
                factor: u.exp(),
                allowed: (lo.exp(), hi.exp()),
                chi2,
                constrained,
                predicted: !constrained || chi2 <= PREDICTION_LIMIT,
            }
        })
        .collect()
}
