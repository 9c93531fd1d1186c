//! 1-D fits of one effect at a time and the decision which effect (if any) explains the gap.
//!
//! A fit never re-simulates per trial value: the simulated predictions at a handful of factors
//! (a "grid", in u = ln factor) are interpolated linearly in u, the χ² of the interpolated
//! prediction is scanned on a fine grid, and the minimum is taken. The workflow adds a
//! simulated point at the interpolated minimum until it stops moving.

use super::effects::Effect;
use super::gap::{chi2_quantile_95, gap, Gap, Prediction};
use super::measured::MeasuredSet;

/// Points of the fine scan between the grid's ends.
const SCAN_POINTS: usize = 801;
/// Two effects whose best χ² differ by less than this explain the data equally well (a
/// likelihood ratio above e⁻¹).
pub const TIE_DELTA_CHI2: f64 = 2.0;
/// The grid point count beyond which no more refinements are made per effect.
pub const MAX_GRID: usize = 7;

/// Simulated predictions of one effect at several factors.
#[derive(Clone, Debug)]
pub struct Grid {
    pub effect: Effect,
    /// (u = ln factor, predictions for every measured curve), sorted by u.
    pub points: Vec<(f64, Vec<Prediction>)>,
}

impl Grid {
    pub fn new(effect: Effect) -> Grid {
        Grid {
            effect,
            points: Vec::new(),
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

    /// χ² along the fine scan: (u, χ²).
    pub fn scan(&self, m: &MeasuredSet) -> Vec<(f64, f64)> {
        let (lo, hi) = (self.points[0].0, self.points[self.points.len() - 1].0);
        (0..SCAN_POINTS)
            .map(|k| {
                let u = lo + (hi - lo) * k as f64 / (SCAN_POINTS - 1) as f64;
                (u, gap(m, &self.interpolate(u)).chi2)
            })
            .collect()
    }

    /// The interpolated minimum (u*, χ²*) and the interval where χ² ≤ χ²* + 1.
    pub fn minimum(&self, m: &MeasuredSet) -> (f64, f64, (f64, f64)) {
        let scan = self.scan(m);
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

/// One effect's best single-parameter explanation of the gap.
#[derive(Clone, Debug)]
pub struct EffectFit {
    pub effect: Effect,
    /// Fitted factor on the config's value and its interval (χ² within +1 of the minimum).
    pub factor: f64,
    pub interval: (f64, f64),
    pub chi2: f64,
    /// 1 − χ²_fit / χ²_baseline: the share of the (squared, noise-normalised) gap it removes.
    pub explained: f64,
    /// χ² at the ends of the plausible range (the sensitivity screen).
    pub chi2_at_range_ends: (f64, f64),
    /// Relative weight exp(−χ²/2) among all fitted effects.
    pub confidence: f64,
    /// Simulated grid points (factors) the fit rests on.
    pub grid_factors: Vec<f64>,
    /// The fit hit the end of the plausible range.
    pub at_range_end: bool,
}

impl EffectFit {
    /// One line: name, factor with its interval, χ², explained share and confidence.
    pub fn summary(&self) -> String {
        format!(
            "{:<24} factor {:>8.3} [{:.3}, {:.3}] chi2 {:>9.2} explained {:>5.1}% confidence {:.2}",
            self.effect.name(),
            self.factor,
            self.interval.0,
            self.interval.1,
            self.chi2,
            100.0 * self.explained,
            self.confidence
        )
    }
}

/// Which effect explains the gap.
#[derive(Clone, Debug, PartialEq)]
pub enum Decision {
    /// The baseline is within sample-to-sample and measurement noise: nothing to explain.
    WithinNoise,
    /// No effect improves χ² significantly (by the 95% quantile of χ² with one degree).
    NoEffectExplains,
    /// One effect, clearly ahead.
    Named(Effect),
    /// Several effects fit equally well (χ² within [`TIE_DELTA_CHI2`]); the data cannot tell
    /// them apart. The first is the (nominally) best.
    Undetermined(Vec<Effect>),
}

/// Fits every grid and decides. `baseline` is the gap of the unchanged model.
pub fn attribute(m: &MeasuredSet, baseline: &Gap, grids: &[Grid]) -> (Vec<EffectFit>, Decision) {
    let mut fits: Vec<EffectFit> = grids
        .iter()
        .map(|g| {
            let (u, chi2, (lo, hi)) = g.minimum(m);
            let ends = (
                gap(m, &g.points[0].1).chi2,
                gap(m, &g.points[g.points.len() - 1].1).chi2,
            );
            let (range_lo, range_hi) = g.effect.range();
            let at_end = (u - range_lo.ln()).abs() < 1e-9 || (u - range_hi.ln()).abs() < 1e-9;
            EffectFit {
                effect: g.effect,
                factor: u.exp(),
                interval: (lo.exp(), hi.exp()),
                chi2,
                explained: 1.0 - chi2 / baseline.chi2,
                chi2_at_range_ends: ends,
                confidence: 0.0,
                grid_factors: g.points.iter().map(|(u, _)| u.exp()).collect(),
                at_range_end: at_end,
            }
        })
        .collect();
    fits.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
    if let Some(best) = fits.first().map(|f| f.chi2) {
        let weights: Vec<f64> = fits
            .iter()
            .map(|f| (-0.5 * (f.chi2 - best)).exp())
            .collect();
        let total: f64 = weights.iter().sum();
        for (f, w) in fits.iter_mut().zip(weights) {
            f.confidence = w / total;
        }
    }
    let decision = decide(baseline, &fits);
    (fits, decision)
}

fn decide(baseline: &Gap, fits: &[EffectFit]) -> Decision {
    if baseline.within_noise() {
        return Decision::WithinNoise;
    }
    let Some(best) = fits.first() else {
        return Decision::NoEffectExplains;
    };
    if baseline.chi2 - best.chi2 < chi2_quantile_95(1) {
        return Decision::NoEffectExplains;
    }
    let tied: Vec<Effect> = fits
        .iter()
        .filter(|f| f.chi2 - best.chi2 < TIE_DELTA_CHI2)
        .map(|f| f.effect)
        .collect();
    if tied.len() > 1 {
        Decision::Undetermined(tied)
    } else {
        Decision::Named(best.effect)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data() -> MeasuredSet {
        MeasuredSet::parse("[[sticking]]\nvelocity_m_s = 2.0\nsigma_m_s = 0.05\n", "t").unwrap()
    }

    fn sticking(v: f64) -> Vec<Prediction> {
        vec![Prediction::Sticking {
            velocity: v,
            resolution: 0.0,
        }]
    }

    /// A grid for an effect whose sticking speed goes as factor^power from 1 m/s.
    fn power_grid(effect: Effect, power: f64, factors: &[f64]) -> Grid {
        let mut g = Grid::new(effect);
        for &f in factors {
            g.insert(f.ln(), sticking(f.powf(power)));
        }
        g
    }

    #[test]
    fn the_fit_recovers_a_power_law_and_refines_where_needed() {
        let m = data();
        let g = power_grid(Effect::NormalDamping, 0.5, &[1.0 / 16.0, 1.0, 64.0]);
        let (u, _, _) = g.minimum(&m);
        // Linear interpolation in u of ln v is exact for a power law: factor 4.
        assert!((u.exp() / 4.0 - 1.0).abs() < 0.01, "{}", u.exp());
        assert!(g.next_point(&m, 0.05).is_some());
    }

    #[test]
    fn decides_named_tied_or_nothing() {
        let m = data();
        let base = gap(&m, &sticking(1.0));
        let strong = power_grid(Effect::NormalDamping, 0.5, &[1.0 / 16.0, 1.0, 4.0, 64.0]);
        let none = power_grid(Effect::RollingStiffness, 0.0, &[1.0 / 8.0, 1.0, 16.0]);
        let (fits, d) = attribute(&m, &base, &[none.clone(), strong.clone()]);
        assert_eq!(d, Decision::Named(Effect::NormalDamping));
        assert!(fits[0].explained > 0.99 && fits[0].confidence > 0.99);
        let twin = power_grid(Effect::SurfaceEnergy, 1.0, &[0.5, 1.0, 2.0, 2.5]);
        let (_, d) = attribute(&m, &base, &[strong, twin]);
        assert_eq!(
            d,
            Decision::Undetermined(vec![Effect::NormalDamping, Effect::SurfaceEnergy])
                .clone()
                .then_sorted(&d)
        );
        let (_, d) = attribute(&m, &base, &[none]);
        assert_eq!(d, Decision::NoEffectExplains);
        let within = gap(&m, &sticking(2.01));
        let (_, d) = attribute(&m, &within, &[]);
        assert_eq!(d, Decision::WithinNoise);
    }

    impl Decision {
        /// The same set of effects in the order `other` lists them (ties are ordered by χ²).
        fn then_sorted(self, other: &Decision) -> Decision {
            match (self, other) {
                (Decision::Undetermined(mut a), Decision::Undetermined(b)) => {
                    a.sort_by_key(|e| b.iter().position(|x| x == e));
                    Decision::Undetermined(a)
                }
                (s, _) => s,
            }
        }
    }
}
