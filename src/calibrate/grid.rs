//! Simulated predictions of one effect at several factors, and the 1-D fit through them: the
//! predictions are interpolated linearly in u = ln factor, the χ² of the interpolated
//! prediction is scanned on a fine grid, and the minimum is taken.

use super::effects::Effect;
use super::gap::{gap, Prediction};
use super::measured::MeasuredSet;

/// χ² must fall by more than this towards a range end for the search to widen there.
pub const FALLING: f64 = 0.1;
/// Points of the fine scan between the grid's ends.
const SCAN_POINTS: usize = 801;
/// The grid point count beyond which no more refinements are made per effect (the screen's
/// three, up to four widenings and three refinements).
pub const MAX_GRID: usize = 10;

/// Simulated predictions of one effect at several factors.
#[derive(Clone, Debug)]
pub struct Grid {
    pub effect: Effect,
    /// (u = ln factor, predictions for every measured curve), sorted by u.
    pub points: Vec<(f64, Vec<Prediction>)>,
    /// Screened points as simulated (before any gain correction), by u.
    pub screened: Vec<(f64, Vec<Prediction>)>,
    /// Full (every-seed) predictions made by the polish: (u, full, the screened reading of
    /// the same runs).
    pub full: Vec<(f64, Vec<Prediction>, Vec<Prediction>)>,
}

impl Grid {
    pub fn new(effect: Effect) -> Grid {
        Grid {
            effect,
            points: Vec::new(),
            screened: Vec::new(),
            full: Vec::new(),
        }
    }

    /// A screened point, kept as simulated for the gain correction too.
    pub fn insert_screened(&mut self, u: f64, predictions: Vec<Prediction>) {
        self.screened.retain(|(x, _)| *x != u);
        self.screened.push((u, predictions.clone()));
        self.insert(u, predictions);
    }

    /// A full prediction at u, with the screened reading of the same runs: the screened
    /// points between the ends are dropped (they would meet the full ones in a kink that the
    /// interpolation reads as a sharp minimum, a falsely narrow interval), and those left are
    /// rescaled by the gain of every pair so far ([`super::fidelity`]).
    pub fn insert_full(
        &mut self,
        u: f64,
        full: Vec<Prediction>,
        screened: Vec<Prediction>,
        current: &[Prediction],
    ) {
        self.insert(u, full.clone());
        self.full.push((u, full, screened));
        let full_at: Vec<f64> = self.full.iter().map(|(x, _, _)| *x).collect();
        let (lo, hi) = self.ends();
        self.points
            .retain(|(x, _)| *x == lo || *x == hi || *x == 0.0 || full_at.contains(x));
        let pairs: Vec<(&[Prediction], &[Prediction])> =
            self.full.iter().map(|(_, f, s)| (&f[..], &s[..])).collect();
        let gains = super::fidelity::gains(current, &pairs);
        for (x, original) in &self.screened {
            if full_at.contains(x) {
                continue;
            }
            if let Some(point) = self.points.iter_mut().find(|(y, _)| y == x) {
                point.1 = super::fidelity::corrected(current, original, &gains);
            }
        }
    }

    pub fn insert(&mut self, u: f64, predictions: Vec<Prediction>) {
        let at = self.points.partition_point(|(x, _)| *x < u);
        if self.points.get(at).is_some_and(|(x, _)| *x == u) {
            self.points[at].1 = predictions;
        } else {
            self.points.insert(at, (u, predictions));
        }
    }

    /// Predictions at u, linear between the neighbouring grid points (clamped at the ends).
    pub fn interpolate(&self, u: f64) -> Vec<Prediction> {
        let p = &self.points;
        let k = p
            .windows(2)
            .position(|w| u <= w[1].0)
            .unwrap_or(p.len().saturating_sub(2));
        if p.len() == 1 {
            return p[0].1.clone();
        }
        let (u0, u1) = (p[k].0, p[k + 1].0);
        let t = ((u - u0) / (u1 - u0)).clamp(0.0, 1.0);
        p[k].1
            .iter()
            .zip(&p[k + 1].1)
            .map(|(a, b)| Prediction::blend(a, b, t))
            .collect()
    }

    /// The simulated ends (u_lo, u_hi).
    pub fn ends(&self) -> (f64, f64) {
        (self.points[0].0, self.points[self.points.len() - 1].0)
    }

    /// Nothing simulated below factor 1: the screen looks upwards only, and the search went
    /// below 1 for this effect only if χ² fell that way.
    pub fn lower_unsearched(&self) -> bool {
        self.points.first().is_some_and(|(u, _)| *u == 0.0)
    }

    /// χ² along the fine scan: (u, χ²).
    pub fn scan(&self, m: &MeasuredSet) -> Vec<(f64, f64)> {
        self.scan_curves(m, &|_| true)
    }

    /// χ² summed over the curves `keep` accepts (by index), along the fine scan.
    pub fn scan_curves(&self, m: &MeasuredSet, keep: &dyn Fn(usize) -> bool) -> Vec<(f64, f64)> {
        let (lo, hi) = self.ends();
        (0..SCAN_POINTS)
            .map(|k| {
                let u = lo + (hi - lo) * k as f64 / (SCAN_POINTS - 1) as f64;
                let g = gap(m, &self.interpolate(u));
                let chi2 = g
                    .curves
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| keep(*j))
                    .map(|(_, c)| c.chi2)
                    .sum();
                (u, chi2)
            })
            .collect()
    }

    /// The interpolated minimum (u*, χ²*) and the interval where χ² ≤ χ²* + 1.
    pub fn minimum(&self, m: &MeasuredSet) -> (f64, f64, (f64, f64)) {
        minimum_of(&self.scan(m))
    }

    /// Whether the interpolated minimum sits on a simulated end: Some(true) on the upper,
    /// Some(false) on the lower end.
    pub fn minimum_at_end(&self, m: &MeasuredSet) -> Option<bool> {
        let (u, _, _) = self.minimum(m);
        let (lo, hi) = self.ends();
        if self.points.len() < 2 {
            None
        } else if (u - hi).abs() < 1e-9 {
            Some(true)
        } else if (u - lo).abs() < 1e-9 {
            Some(false)
        } else {
            None
        }
    }

    /// The minimum sits on an end and χ² there is below the neighbouring simulated factor's
    /// by more than [`FALLING`]: going further that way may help. The margin is small on
    /// purpose: an effect can be weak at the screen's end and strong beyond it (viscous
    /// damping ×4 of the paper's κ lowers the Poppe χ² by 0.5, ×500 closes it).
    pub fn end_still_falling(&self, m: &MeasuredSet) -> bool {
        let Some(upper) = self.minimum_at_end(m) else {
            return false;
        };
        let n = self.points.len();
        let (end, inner) = if upper {
            (&self.points[n - 1].1, &self.points[n - 2].1)
        } else {
            (&self.points[0].1, &self.points[1].1)
        };
        gap(m, end).chi2 < gap(m, inner).chi2 - FALLING
    }

    /// Where to widen the search: the next end (in u) beyond the one the minimum sits on,
    /// twice as far from the config's value (from factor 1 itself: the screen's end of the
    /// range that way), up to the effect's limits; None when the minimum is interior or the
    /// end already is the limit.
    pub fn widen_point(&self, m: &MeasuredSet) -> Option<f64> {
        if self.points.len() >= MAX_GRID {
            return None;
        }
        let upper = self.minimum_at_end(m)?;
        let (lo, hi) = self.ends();
        let (limit_lo, limit_hi, _) = self.effect.limits();
        let (end, limit) = if upper {
            (hi, limit_hi.ln())
        } else {
            (lo, limit_lo.ln())
        };
        if (end - limit).abs() < 1e-9 {
            return None;
        }
        // From factor 1 (a one-sided screen) the first step down is the screen's lower end.
        let next = if end == 0.0 {
            let (lo, hi) = self.effect.range();
            if upper {
                hi.ln()
            } else {
                lo.ln()
            }
        } else {
            2.0 * end
        };
        Some(if upper {
            next.min(limit)
        } else {
            next.max(limit)
        })
    }

    /// Where to simulate next to pin the minimum down, or None when the interpolated minimum
    /// lies within `tolerance` (in u) of a simulated point.
    pub fn next_point(&self, m: &MeasuredSet, tolerance: f64) -> Option<f64> {
        if self.points.len() >= MAX_GRID {
            return None;
        }
        let (u, _, _) = self.minimum(m);
        let nearest = self
            .points
            .iter()
            .map(|(x, _)| (x - u).abs())
            .fold(f64::INFINITY, f64::min);
        (nearest > tolerance).then_some(u)
    }
}

/// The minimum of a scan (u*, χ²*) and the interval where χ² ≤ χ²* + 1.
pub(super) fn minimum_of(scan: &[(f64, f64)]) -> (f64, f64, (f64, f64)) {
    let best = scan
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("non-empty scan");
    let inside: Vec<f64> = scan
        .iter()
        .filter(|(_, c)| *c <= best.1 + 1.0)
        .map(|(u, _)| *u)
        .collect();
    let lo = inside.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = inside.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (best.0, best.1, (lo, hi))
}
