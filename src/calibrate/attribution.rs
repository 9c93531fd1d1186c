//! 1-D fits of one effect at a time and the decision which effect (if any) explains the gap.
//!
//! A fit never re-simulates per trial value: the simulated predictions at a handful of factors
//! (a "grid", in u = ln factor) are interpolated linearly in u, the χ² of the interpolated
//! prediction is scanned on a fine grid, and the minimum is taken. The workflow adds a
//! simulated point at the interpolated minimum until it stops moving.

pub use super::detection::{detection_limit, DetectionLimit};
use super::effects::Effect;
use super::gap::{chi2_quantile_95, gap, Gap};
pub use super::grid::{Grid, FALLING, MAX_GRID};
pub use super::held_out::{held_out, HeldOut};
use super::measured::MeasuredSet;
pub use super::outside::SingleObservable;
use super::outside::{outside_library, single_observable};

/// Two effects whose best χ² differ by less than this explain the data equally well (a
/// likelihood ratio above e⁻¹).
pub const TIE_DELTA_CHI2: f64 = 2.0;

/// A fit that landed on the end of the searched range: the data ask for at least (upper) or
/// at most this factor.
#[derive(Clone, Debug, PartialEq)]
pub struct Bound {
    pub upper: bool,
    /// The end is the effect's limit (the search may not go further), with the reason.
    pub limit: Option<&'static str>,
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
    /// The fit landed on the end of the searched range: the factor is a bound.
    pub bound: Option<Bound>,
    /// Each curve predicted by the fit to the others.
    pub held_out: Vec<HeldOut>,
}

impl EffectFit {
    /// One line: name, factor (or bound) with its interval, χ², explained share, confidence
    /// and the curves it fails to predict.
    pub fn summary(&self) -> String {
        let fails = self.failed_predictions();
        format!(
            "{:<24} factor {:>10} [{:.3}, {:.3}] chi2 {:>9.2} explained {:>5.1}% confidence {:.2}{}",
            self.effect.name(),
            self.factor_text(),
            self.interval.0,
            self.interval.1,
            self.chi2,
            100.0 * self.explained,
            self.confidence,
            if fails.is_empty() {
                String::new()
            } else {
                format!("; does not predict {}", fails.join(", "))
            }
        )
    }

    /// "1.93", or "≥ 4" when the fit is a bound.
    pub fn factor_text(&self) -> String {
        match &self.bound {
            None => format!("{:.3}", self.factor),
            Some(b) => format!("{} {:.3}", if b.upper { ">=" } else { "<=" }, self.factor),
        }
    }

    /// The curves this effect, fitted to the others, does not predict within noise.
    pub fn failed_predictions(&self) -> Vec<String> {
        self.held_out
            .iter()
            .filter(|h| !h.predicted)
            .map(|h| h.curve.clone())
            .collect()
    }
}

/// Which effect explains the gap.
#[derive(Clone, Debug, PartialEq)]
pub enum Decision {
    /// The baseline is within sample-to-sample and measurement noise: nothing to explain.
    WithinNoise,
    /// No effect improves χ² significantly (by the 95% quantile of χ² with one degree).
    NoEffectExplains,
    /// One effect, clearly ahead, that also predicts every curve it was not fitted to.
    Named(Effect),
    /// The best effect, clearly ahead, fits the curves jointly but fitted without some curve
    /// it does not predict it: no effect in the library explains all curves. It is applied as
    /// the best partial explanation.
    Unpredictive { effect: Effect, fails: Vec<String> },
    /// Two effects fitted jointly beat every single effect by more than χ²₉₅(1), and no
    /// other pair comes near ([`super::pairs::reconsider`]).
    NamedPair([Effect; 2]),
    /// Several explanations fit equally well (χ² within [`TIE_DELTA_CHI2`]): single effects
    /// and pairs that need both their effects; the data cannot tell them apart. The first
    /// single (or, with none, the first pair) is the (nominally) best.
    Undetermined {
        singles: Vec<Effect>,
        pairs: Vec<[Effect; 2]>,
    },
}

impl Decision {
    /// The effect the workflow applies, if any.
    pub fn chosen(&self) -> Option<Effect> {
        match self {
            Decision::Named(e) | Decision::Unpredictive { effect: e, .. } => Some(*e),
            Decision::Undetermined { singles, .. } => singles.first().copied(),
            Decision::WithinNoise | Decision::NoEffectExplains | Decision::NamedPair(_) => None,
        }
    }

    /// The pair the workflow applies, if any: a named pair, or the nominally best pair of an
    /// undetermined result without a single effect among its candidates.
    pub fn chosen_pair(&self) -> Option<[Effect; 2]> {
        match self {
            Decision::NamedPair(p) => Some(*p),
            Decision::Undetermined { singles, pairs } if singles.is_empty() => {
                pairs.first().copied()
            }
            _ => None,
        }
    }

    /// Several explanations are left open.
    pub fn is_undetermined(&self) -> bool {
        matches!(self, Decision::Undetermined { .. })
    }
}

/// A left-out curve counts as predicted below the 99% quantile of χ² with one degree (6.63),
/// not the 95% one: with three curves a true effect would otherwise fail a prediction by
/// chance in one data set of seven.
pub const PREDICTION_LIMIT: f64 = 6.63;

/// Fits every grid and decides. `baseline` is the gap of the unchanged model.
pub fn attribute(m: &MeasuredSet, baseline: &Gap, grids: &[Grid]) -> (Vec<EffectFit>, Decision) {
    let mut fits: Vec<EffectFit> = grids
        .iter()
        .map(|g| {
            let (u, chi2, (lo, hi)) = g.minimum(m);
            // Below factor 1 nothing may have been simulated (NaN: not run).
            let lower_end = if g.lower_unsearched() {
                f64::NAN
            } else {
                gap(m, &g.points[0].1).chi2
            };
            let ends = (lower_end, gap(m, &g.points[g.points.len() - 1].1).chi2);
            let (limit_lo, limit_hi, why) = g.effect.limits();
            // A minimum at factor 1 with nothing searched below is no bound: χ² did not fall
            // that way (or the effect was dropped), so the effect changes nothing for the better.
            let at_end = g
                .minimum_at_end(m)
                .filter(|&upper| upper || !g.lower_unsearched());
            let bound = at_end.map(|upper| {
                let limit = if upper { limit_hi } else { limit_lo };
                Bound {
                    upper,
                    limit: ((u - limit.ln()).abs() < 1e-9).then_some(why),
                }
            });
            let held_out = held_out(m, g);
            EffectFit {
                effect: g.effect,
                factor: u.exp(),
                interval: (lo.exp(), hi.exp()),
                chi2,
                explained: 1.0 - chi2 / baseline.chi2,
                chi2_at_range_ends: ends,
                confidence: 0.0,
                grid_factors: g.points.iter().map(|(u, _)| u.exp()).collect(),
                bound,
                held_out,
            }
        })
        .collect();
    fits.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
    let single = single_observable(m, baseline, grids);
    let decision = decide(baseline, &fits);
    let outside_candidates = outside_library(baseline, &fits, &decision, !m.compression.is_empty())
        .map_or(Vec::new(), |o| o.candidates);
    if let Some(best) = fits.first().map(|f| f.chi2) {
        let weights: Vec<f64> = fits
            .iter()
            .map(|f| (-0.5 * (f.chi2 - best)).exp())
            .collect();
        // With one observable, each parameter outside the library that moves it is as
        // good an explanation a priori as the best fit; so is each candidate outside the
        // library when the fits tie, sit on a bound or leave the gap beyond noise.
        let mut outside: Vec<String> = single.as_ref().map_or(Vec::new(), |s| {
            s.outside.iter().map(|o| o.to_string()).collect()
        });
        for c in outside_candidates {
            if !outside.contains(&c) {
                outside.push(c);
            }
        }
        let outside = outside.len() as f64;
        // The damping's two forms are one explanation: only each family's best counts.
        let total: f64 = fits
            .iter()
            .zip(&weights)
            .enumerate()
            .filter(|(k, (f, _))| {
                !fits[..*k]
                    .iter()
                    .any(|g| g.effect.family() == f.effect.family())
            })
            .map(|(_, (_, w))| w)
            .sum::<f64>()
            + outside;
        for (f, w) in fits.iter_mut().zip(weights) {
            f.confidence = w / total;
        }
    }
    (fits, decision)
}

/// One fit per family (the damping in either form is one effect): the better form, unless the
/// config's own form is within [`TIE_DELTA_CHI2`] of it. `fits` is sorted by χ².
fn family_representatives(fits: &[EffectFit]) -> Vec<&EffectFit> {
    let mut reps: Vec<&EffectFit> = Vec::new();
    for f in fits {
        if reps.iter().any(|r| r.effect.family() == f.effect.family()) {
            continue;
        }
        let own_form = fits.iter().find(|g| {
            g.effect.family() == f.effect.family()
                && g.effect.identity_at_one()
                && g.chi2 - f.chi2 < TIE_DELTA_CHI2
        });
        reps.push(own_form.unwrap_or(f));
    }
    reps.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
    reps
}

fn decide(baseline: &Gap, fits: &[EffectFit]) -> Decision {
    if baseline.within_noise() {
        return Decision::WithinNoise;
    }
    let reps = family_representatives(fits);
    let Some(best) = reps.first() else {
        return Decision::NoEffectExplains;
    };
    if baseline.chi2 - best.chi2 < chi2_quantile_95(1) {
        return Decision::NoEffectExplains;
    }
    let tied: Vec<Effect> = reps
        .iter()
        .filter(|f| f.chi2 - best.chi2 < TIE_DELTA_CHI2)
        .map(|f| f.effect)
        .collect();
    if tied.len() > 1 {
        return Decision::Undetermined {
            singles: tied,
            pairs: Vec::new(),
        };
    }
    let fails = best.failed_predictions();
    if fails.is_empty() {
        Decision::Named(best.effect)
    } else {
        Decision::Unpredictive {
            effect: best.effect,
            fails,
        }
    }
}

#[cfg(test)]
mod tests;
