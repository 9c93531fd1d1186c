//! Two effects fitted jointly, and the decision revisited with them.
//!
//! One effect can stand in for two on a few curves: a stiffness with a damping change can look
//! like the other damping form at a larger coefficient. So after the 1-D fits every pair of
//! effects of two families is fitted in 2-D on the simulated responses, added to the current
//! model: p(u₁, u₂) = g₁(u₁) + g₂(u₂) − current, each g interpolated in its own grid as the 1-D
//! fits do (no new runs). A pair counts only when it needs both of its effects: it fits better
//! than either effect alone by more than χ²₉₅ with one degree. The pairs the decision rests on
//! are then simulated with both effects applied, on every seed ([`PairFit::simulated_chi2`]).

use super::attribution::{Decision, DetectionLimit, EffectFit, TIE_DELTA_CHI2};
use super::effects::Effect;
use super::gap::{chi2_quantile_95, gap, Prediction};
use super::grid::Grid;
use super::measured::MeasuredSet;

/// Points per axis of the coarse 2-D scan over both grids' simulated ranges.
const COARSE: usize = 33;
/// Points per axis of the fine scan around the coarse minimum (± two coarse steps).
const FINE: usize = 17;
/// Pairs simulated per round at most (the best by screened χ² of those the decision rests on).
pub const CONFIRMED_PAIRS: usize = 6;

/// The best joint fit of two effects.
#[derive(Clone, Debug, PartialEq)]
pub struct PairFit {
    pub effects: [Effect; 2],
    pub factors: [f64; 2],
    /// Each factor's interval: χ² within +1 of the minimum, the other factor free (profile).
    pub intervals: [(f64, f64); 2],
    /// χ² of the interpolated joint prediction at the fitted factors.
    pub chi2: f64,
    /// χ² of each effect alone: its own 1-D fit, or the pair's scan with the other at
    /// factor 1 where that is lower.
    pub alone: [f64; 2],
    /// The factor sits on the end of its grid's simulated range: a bound, not a fit.
    pub on_bound: [bool; 2],
    /// Set for a fit with this effect (0 or 1) held at or beyond its detection limit: the
    /// best the pair does with that effect present at a level the data would show alone.
    /// Such a fit is an alternative to the other effect alone when it fits as well; it is
    /// never named (it is constrained).
    pub pinned: Option<usize>,
    /// χ² simulated with both effects applied at the fitted factors on every seed.
    pub simulated_chi2: Option<f64>,
}

impl PairFit {
    /// The χ² the decision uses: simulated where the pair was simulated.
    pub fn chi2_used(&self) -> f64 {
        self.simulated_chi2.unwrap_or(self.chi2)
    }

    /// Both effects are needed: the pair beats each alone by more than χ²₉₅(1). A pinned fit
    /// holds one at a detectable level by construction and needs the other to beat it.
    pub fn needs_both(&self) -> bool {
        let q = chi2_quantile_95(1);
        match self.pinned {
            None => self.alone.iter().all(|a| a - self.chi2_used() > q),
            Some(k) => self.alone[k] - self.chi2_used() > q,
        }
    }

    pub fn contains(&self, e: Effect) -> bool {
        self.effects.contains(&e)
    }

    /// "rolling_stiffness x4.02 [3.1, 5.3] + normal_damping >= x4.00 [...]".
    pub fn label(&self) -> String {
        let one = |k: usize| {
            format!(
                "{} {}x{:.3} [{:.3}, {:.3}]",
                self.effects[k].name(),
                if self.on_bound[k] { "bound " } else { "" },
                self.factors[k],
                self.intervals[k].0,
                self.intervals[k].1
            )
        };
        format!("{} + {}", one(0), one(1))
    }

    pub fn names(&self) -> String {
        let pinned = |k: usize| match self.pinned == Some(k) {
            true => " (at its detection limit or beyond)",
            false => "",
        };
        format!(
            "{}{} + {}{}",
            self.effects[0].name(),
            pinned(0),
            self.effects[1].name(),
            pinned(1)
        )
    }
}

/// a + b − current: two responses added to the model they were simulated from (φ added,
/// sticking speeds multiplied, scatter the larger of the two).
pub fn combine(current: &Prediction, a: &Prediction, b: &Prediction) -> Prediction {
    match (current, a, b) {
        (
            Prediction::Compression { phi: pc, seeds, .. },
            Prediction::Compression {
                phi: pa,
                scatter: sa,
                ..
            },
            Prediction::Compression {
                phi: pb,
                scatter: sb,
                ..
            },
        ) => Prediction::Compression {
            phi: (0..pc.len()).map(|k| pa[k] + pb[k] - pc[k]).collect(),
            scatter: sa.iter().zip(sb).map(|(x, y)| x.max(*y)).collect(),
            seeds: *seeds,
        },
        (
            Prediction::Sticking { velocity: vc, .. },
            Prediction::Sticking {
                velocity: va,
                resolution: ra,
            },
            Prediction::Sticking {
                velocity: vb,
                resolution: rb,
            },
        ) => Prediction::Sticking {
            velocity: va * vb / vc,
            resolution: ra.max(*rb),
        },
        _ => panic!("combining predictions of different curves"),
    }
}

/// Curves a data set needs before pairs are fitted: a pair fits two curves exactly whatever
/// the truth, so only a third can tell a pair from a single effect.
pub const PAIR_MIN_CURVES: usize = 3;

/// Every pair of grids of two families, fitted jointly, sorted by χ² (best first); and for
/// each pair and each of its effects with a detection limit, the joint fit with that effect
/// held at or beyond its limit ([`PairFit::pinned`]). None with fewer than
/// [`PAIR_MIN_CURVES`] curves.
pub fn fit_pairs(
    m: &MeasuredSet,
    grids: &[Grid],
    current: &[Prediction],
    fits: &[EffectFit],
    detection: &[DetectionLimit],
) -> Vec<PairFit> {
    let mut pairs = Vec::new();
    if m.curve_count() < PAIR_MIN_CURVES {
        return pairs;
    }
    for (i, a) in grids.iter().enumerate() {
        for b in &grids[i + 1..] {
            if a.effect.family() == b.effect.family() || a.points.len() < 2 || b.points.len() < 2 {
                continue;
            }
            pairs.extend(fit_pair(m, [a, b], current, fits, detection));
        }
    }
    pairs.sort_by(|x, y| x.chi2.total_cmp(&y.chi2));
    pairs
}

/// Evenly spaced u over [lo, hi], `n` points.
fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// χ² on the product of two axes: rows follow `ua`, columns `ub`.
fn chi2_table(
    m: &MeasuredSet,
    grids: [&Grid; 2],
    current: &[Prediction],
    ua: &[f64],
    ub: &[f64],
) -> Vec<Vec<f64>> {
    let pb: Vec<Vec<Prediction>> = ub.iter().map(|&u| grids[1].interpolate(u)).collect();
    ua.iter()
        .map(|&u| {
            let pa = grids[0].interpolate(u);
            pb.iter()
                .map(|pb| {
                    let joint: Vec<Prediction> = (0..current.len())
                        .map(|k| combine(&current[k], &pa[k], &pb[k]))
                        .collect();
                    gap(m, &joint).chi2
                })
                .collect()
        })
        .collect()
}

/// The lowest cell of a table among those `keep(i, j)` allows: (i, j, χ²).
fn argmin(table: &[Vec<f64>], keep: impl Fn(usize, usize) -> bool) -> Option<(usize, usize, f64)> {
    let mut best: Option<(usize, usize, f64)> = None;
    for (i, row) in table.iter().enumerate() {
        for (j, &c) in row.iter().enumerate() {
            if keep(i, j) && best.is_none_or(|b| c < b.2) {
                best = Some((i, j, c));
            }
        }
    }
    best
}

/// The interval of one axis where the profile (minimum over the other axis) is within +1 of
/// `min`: the outermost axis points inside, one step out where the next is outside (a
/// conservative reading of a sampled scan).
fn profile_interval(u: &[f64], profile: &[f64], min: f64) -> (f64, f64) {
    let inside: Vec<usize> = (0..u.len()).filter(|&k| profile[k] <= min + 1.0).collect();
    let (first, last) = match (inside.first(), inside.last()) {
        (Some(&f), Some(&l)) => (f, l),
        _ => return (f64::NAN, f64::NAN),
    };
    (
        u[first.saturating_sub(1)].exp(),
        u[(last + 1).min(u.len() - 1)].exp(),
    )
}

/// The coarse axis with a fine stretch (± two coarse steps) around `k`, sorted.
fn refined(coarse: &[f64], k: usize) -> Vec<f64> {
    let lo = coarse[k.saturating_sub(2)];
    let hi = coarse[(k + 2).min(coarse.len() - 1)];
    let mut u: Vec<f64> = coarse.iter().copied().chain(axis(lo, hi, FINE)).collect();
    u.sort_by(f64::total_cmp);
    u.dedup();
    u
}

/// Whether u lies at or beyond the detection limit of `d` (either way).
fn detectable(d: &DetectionLimit, u: f64) -> bool {
    d.lower.is_some_and(|l| u <= l.ln() + 1e-12) || d.upper.is_some_and(|h| u >= h.ln() - 1e-12)
}

fn fit_pair(
    m: &MeasuredSet,
    grids: [&Grid; 2],
    current: &[Prediction],
    fits: &[EffectFit],
    detection: &[DetectionLimit],
) -> Vec<PairFit> {
    let ends = grids.map(|g| g.ends());
    let coarse = [0, 1].map(|k| axis(ends[k].0, ends[k].1, COARSE));
    let table = chi2_table(m, grids, current, &coarse[0], &coarse[1]);
    let (i, j, _) = argmin(&table, |_, _| true).expect("a scan");
    let (ua, ub) = (refined(&coarse[0], i), refined(&coarse[1], j));
    let table = chi2_table(m, grids, current, &ua, &ub);
    let (i, j, chi2) = argmin(&table, |_, _| true).expect("a scan");
    let rows: Vec<f64> = table
        .iter()
        .map(|r| r.iter().copied().fold(f64::INFINITY, f64::min))
        .collect();
    let cols: Vec<f64> = (0..ub.len())
        .map(|c| table.iter().map(|r| r[c]).fold(f64::INFINITY, f64::min))
        .collect();
    let own = |e: Effect| {
        fits.iter()
            .find(|f| f.effect == e)
            .map_or(f64::INFINITY, |f| f.chi2)
    };
    // Each effect alone: its 1-D fit, or the scan with the other at factor 1 (u = 0) where
    // the other grid has the model unchanged there.
    let alone_on_axis = |k: usize| -> f64 {
        let other = grids[1 - k];
        if !other.effect.identity_at_one() || !(other.ends().0..=other.ends().1).contains(&0.0) {
            return f64::INFINITY;
        }
        let zero = [0.0];
        let t = match k {
            0 => chi2_table(m, grids, current, &coarse[0], &zero),
            _ => chi2_table(m, grids, current, &zero, &coarse[1]),
        };
        t.iter().flatten().copied().fold(f64::INFINITY, f64::min)
    };
    let alone = [0, 1].map(|k| own(grids[k].effect).min(alone_on_axis(k)));
    let at_end = |u: f64, (lo, hi): (f64, f64)| (u - lo).abs() < 1e-9 || (u - hi).abs() < 1e-9;
    let free = PairFit {
        effects: [grids[0].effect, grids[1].effect],
        factors: [ua[i].exp(), ub[j].exp()],
        intervals: [
            profile_interval(&ua, &rows, chi2),
            profile_interval(&ub, &cols, chi2),
        ],
        chi2,
        alone,
        on_bound: [at_end(ua[i], ends[0]), at_end(ub[j], ends[1])],
        pinned: None,
        simulated_chi2: None,
    };
    let mut out = vec![free.clone()];
    for k in 0..2 {
        let Some(d) = detection.iter().find(|d| d.effect == grids[k].effect) else {
            continue;
        };
        let beyond = |i: usize, j: usize| detectable(d, if k == 0 { ua[i] } else { ub[j] });
        if let Some((i, j, chi2)) = argmin(&table, beyond) {
            out.push(PairFit {
                factors: [ua[i].exp(), ub[j].exp()],
                chi2,
                on_bound: [at_end(ua[i], ends[0]), at_end(ub[j], ends[1])],
                pinned: Some(k),
                ..free.clone()
            });
        }
    }
    out
}

/// The pairs a decision from single effects must answer to: those that need both effects and
/// fit within [`TIE_DELTA_CHI2`] of the best single effect, or better; a pinned fit only when
/// it fits better than the best single effect by more than [`TIE_DELTA_CHI2`] (the data
/// prefer the partner present at a level they would show alone). At Δχ² = 0 a true single
/// effect on three samples per curve lost its name to a partner at its detection limit
/// (surface energy ×2: χ² 3.17 alone, 1.49 with the density at its limit).
pub fn rival_pairs(pairs: &[PairFit], best_single: f64) -> Vec<&PairFit> {
    let margin = |p: &PairFit| match p.pinned {
        None => TIE_DELTA_CHI2,
        Some(_) => -TIE_DELTA_CHI2,
    };
    let mut rivals: Vec<&PairFit> = pairs
        .iter()
        .filter(|p| p.needs_both() && p.chi2_used() < best_single + margin(p))
        .collect();
    rivals.sort_by(|a, b| a.chi2_used().total_cmp(&b.chi2_used()));
    rivals
}

/// The pair with these effects the decision rests on: simulated before interpolated, then
/// the lowest χ².
pub fn find_pair(pairs: &[PairFit], effects: [Effect; 2]) -> Option<&PairFit> {
    pairs
        .iter()
        .filter(|p| p.effects == effects)
        .min_by(|a, b| {
            (a.simulated_chi2.is_none(), a.chi2_used())
                .partial_cmp(&(b.simulated_chi2.is_none(), b.chi2_used()))
                .expect("finite")
        })
}

/// The effects of each pair, once, in order.
fn distinct(pairs: &[&PairFit]) -> Vec<[Effect; 2]> {
    let mut out: Vec<[Effect; 2]> = Vec::new();
    for p in pairs {
        if !out.contains(&p.effects) {
            out.push(p.effects);
        }
    }
    out
}

/// The decision from single effects, revisited with the pairs: a single effect stays named
/// only when no pair that needs both its effects fits within [`TIE_DELTA_CHI2`] of it, and no
/// pair with one effect held at its detection limit (the single effect with another at a
/// level the data would show alone) fits better by more than that; a pair fitted freely is named when it beats every
/// single effect by more than χ²₉₅(1) (one more parameter) and no other pair comes within
/// [`TIE_DELTA_CHI2`] of it; otherwise the result is undetermined, with every single effect
/// and pair within reach listed.
pub fn reconsider(single: Decision, fits: &[EffectFit], pairs: &[PairFit]) -> Decision {
    let best_single = fits.iter().map(|f| f.chi2).fold(f64::INFINITY, f64::min);
    let rivals = rival_pairs(pairs, best_single);
    let (singles, explains) = match &single {
        Decision::WithinNoise | Decision::NamedPair(_) => return single,
        Decision::NoEffectExplains => (Vec::new(), false),
        Decision::Named(e) | Decision::Unpredictive { effect: e, .. } => (vec![*e], true),
        Decision::Undetermined { singles, .. } => (singles.clone(), true),
    };
    if rivals.is_empty() {
        return single;
    }
    let best_free = rivals.iter().find(|p| p.pinned.is_none());
    let wanted = best_free.filter(|p| p.chi2_used() < best_single - chi2_quantile_95(1));
    if let Some(best) = wanted {
        let near: Vec<&PairFit> = rivals
            .iter()
            .filter(|p| p.chi2_used() < best.chi2_used() + TIE_DELTA_CHI2)
            .copied()
            .collect();
        let near = distinct(&near);
        return match near.len() {
            1 => Decision::NamedPair(best.effects),
            _ => Decision::Undetermined {
                singles: Vec::new(),
                pairs: near,
            },
        };
    }
    if !explains {
        return single;
    }
    Decision::Undetermined {
        singles,
        pairs: distinct(&rivals),
    }
}

#[cfg(test)]
mod tests;
