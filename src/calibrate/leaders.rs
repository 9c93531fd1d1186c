//! The leaders of a round: the effects within Δχ² = 2 of the best fit are run once on every
//! seed at their fitted factors (which rescales their screened points by the gain those runs
//! show, [`super::fidelity`]), the fits redone, and the chosen effect re-run while its fit
//! moves.

use super::attribution::{attribute, Decision, EffectFit, Grid};
use super::effects::Effect;
use super::gap::{gap, Gap, Prediction};
use super::pairs::{reconsider, rival_pairs, PairFit, CONFIRMED_PAIRS};
use super::predictor::Predictor;
use super::search::{polish, Current, PRUNE_DELTA_CHI2};

/// An effect with the factor it was simulated at on every seed, and those predictions.
pub type Polished = (Effect, f64, Vec<Prediction>);

/// Fits and decides, with the leading effects' factors re-fitted on every seed: each effect
/// within Δχ² = 2 of the best fit is run once on every seed at its fit ([`polish`], which
/// rescales its screened points by the gain that run shows) and the fits redone, until the
/// leaders have all been run (at most `candidates` + 1 effects); the chosen effect is then
/// re-run at its fit while the fit moves by more than the refinement tolerance. With every
/// seed screened only the chosen effect is re-run, at its fitted factor.
pub fn polish_leaders(
    predictor: &mut Predictor,
    now: &Current,
    grids: &mut [Grid],
    before: &Gap,
    round: usize,
) -> Result<(Vec<EffectFit>, Decision, Vec<Polished>), String> {
    let settings = predictor.settings;
    let measured = predictor.measured;
    let screened_all = predictor.screens_every_seed(now.config);
    let limit = if screened_all {
        1
    } else {
        settings.candidates.max(1) + 1
    };
    let (mut fits, mut decision) = attribute(measured, before, grids);
    let mut polished: Vec<Polished> = Vec::new();
    // The leaders are polished also when the screened fits name nothing: a screened response
    // weaker than the mean one can hide an effect that lowers χ² significantly.
    while polished.len() < limit {
        let best = fits.iter().map(|f| f.chi2).fold(f64::INFINITY, f64::min);
        let leaders: Vec<(Effect, f64)> = if screened_all {
            let Some(e) = decision.chosen() else { break };
            vec![(e, fitted_factor(&fits, e))]
        } else {
            fits.iter()
                .filter(|f| f.chi2 <= best + PRUNE_DELTA_CHI2)
                .filter(|f| !polished.iter().any(|p| p.0 == f.effect))
                .map(|f| (f.effect, f.factor))
                .collect()
        };
        if leaders.is_empty() {
            break;
        }
        for (effect, factor) in leaders.into_iter().take(limit - polished.len()) {
            let grid = grids.iter_mut().find(|g| g.effect == effect).expect("grid");
            let (run_factor, predictions) = polish(predictor, now, grid, factor, round)?;
            polished.push((effect, run_factor, predictions));
        }
        (fits, decision) = attribute(measured, before, grids);
    }
    // The chosen effect (the re-fits can reorder a tie) is run at its fit until the fit stops
    // moving; one run per pass, at most `refinements` passes.
    let mut passes = 0;
    while let Some(effect) = decision.chosen() {
        let fitted = fitted_factor(&fits, effect);
        let at = polished.iter().position(|p| p.0 == effect);
        let moved = at.is_none_or(|k| {
            !screened_all && (fitted.ln() - polished[k].1.ln()).abs() > settings.refine_tolerance
        });
        if !moved || passes >= settings.refinements.max(1) {
            break;
        }
        let grid = grids.iter_mut().find(|g| g.effect == effect).expect("grid");
        let (run_factor, predictions) = polish(predictor, now, grid, fitted, round)?;
        match at {
            Some(k) => polished[k] = (effect, run_factor, predictions),
            None => polished.push((effect, run_factor, predictions)),
        }
        passes += 1;
        (fits, decision) = attribute(measured, before, grids);
    }
    // The chosen effect is applied at its fitted factor, simulated on every seed (4% off the
    // fit moved a damping correction's χ² from within noise to beyond it).
    if let Some(effect) = decision.chosen() {
        let fitted = fitted_factor(&fits, effect);
        if let Some(p) = polished.iter_mut().find(|p| p.0 == effect) {
            if fitted != p.1 {
                let config = effect.apply(now.config, fitted);
                let what = format!("round {round}: re-run with {} at its fit", effect.name());
                p.2 = predictor.predict(&[config], &what)?.remove(0);
                p.1 = fitted;
            }
        }
    }
    Ok((fits, decision, polished))
}

/// The factor `effect`'s fit found (every screened effect is fitted).
fn fitted_factor(fits: &[EffectFit], effect: Effect) -> f64 {
    fits.iter()
        .find(|f| f.effect == effect)
        .expect("fitted")
        .factor
}

/// A pair with its fitted factors and its predictions simulated on every seed.
pub type PolishedPair = ([(Effect, f64); 2], Vec<Prediction>);

/// The pairs the decision rests on ([`rival_pairs`]), simulated with both effects applied at
/// their joint fit on every seed (at most [`CONFIRMED_PAIRS`], best first), and the decision
/// revisited with each simulated χ² until no unsimulated pair is left among its rivals. The
/// decision returned counts the simulated pairs only: an interpolated joint fit is no
/// evidence (a damping with a surface energy came out at χ² 3.19 added and 20.17 simulated).
/// Returns the decision, the pairs (simulated χ² set where run) and the simulated pairs.
pub fn confirm_pairs(
    predictor: &mut Predictor,
    now: &Current,
    fits: &[EffectFit],
    mut pairs: Vec<PairFit>,
    single: Decision,
    round: usize,
) -> Result<(Decision, Vec<PairFit>, Vec<PolishedPair>), String> {
    let measured = predictor.measured;
    let best_single = fits.iter().map(|f| f.chi2).fold(f64::INFINITY, f64::min);
    let mut simulated: Vec<PolishedPair> = Vec::new();
    loop {
        let decision = reconsider(single.clone(), fits, &pairs);
        let confirmed: Vec<PairFit> = pairs
            .iter()
            .filter(|p| p.simulated_chi2.is_some())
            .cloned()
            .collect();
        let settled = reconsider(single.clone(), fits, &confirmed);
        let next = rival_pairs(&pairs, best_single)
            .into_iter()
            .find(|p| p.simulated_chi2.is_none())
            .map(|p| (p.effects, p.pinned));
        let (Some(effects), true) = (next, simulated.len() < CONFIRMED_PAIRS) else {
            return Ok((settled, pairs, simulated));
        };
        if matches!(decision, Decision::WithinNoise) {
            return Ok((settled, pairs, simulated));
        }
        let k = pairs
            .iter()
            .position(|p| (p.effects, p.pinned) == effects)
            .expect("pair");
        // A pinned fit whose free fit already held the partner beyond its limit is the same
        // model: its simulated χ² is the free one's.
        let twin = pairs.iter().find(|q| {
            q.simulated_chi2.is_some()
                && q.effects == pairs[k].effects
                && q.factors == pairs[k].factors
        });
        if let Some(c) = twin.and_then(|q| q.simulated_chi2) {
            pairs[k].simulated_chi2 = Some(c);
            continue;
        }
        let p = &mut pairs[k];
        let both = [(p.effects[0], p.factors[0]), (p.effects[1], p.factors[1])];
        let config = both
            .iter()
            .fold(now.config.clone(), |c, (e, f)| e.apply(&c, *f));
        let what = format!("round {round}: pair {} at its joint fit", p.names());
        let predictions = predictor.predict(&[config], &what)?.remove(0);
        p.simulated_chi2 = Some(gap(measured, &predictions).chi2);
        (predictor.progress)(&format!(
            "{what}: chi2 {:.2} interpolated, {:.2} simulated",
            p.chi2,
            p.simulated_chi2.unwrap()
        ));
        simulated.push((both, predictions));
    }
}
