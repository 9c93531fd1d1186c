//! Revisits (`--revisit`): rounds add effects one at a time, so an earlier round fits its
//! effect with the later ones missing and may choose one that stands in for part of them (a
//! damping that also bends the omni curve that stronger side walls bend). After the rounds,
//! each applied effect is searched for again with the others in.

use super::effects::Effect;
use super::gap::{gap, Prediction};
use super::predictor::Predictor;
use super::round::{search_round, Round};
use super::search::Current;
use crate::config::Config;

/// An applied effect searched for again once the effects of the later rounds are in.
#[derive(Clone, Debug)]
pub struct Revisit {
    /// Its place among the applied effects, and what it was before.
    pub of: usize,
    pub was: (Effect, f64),
    /// The other applied effects as they stood then: the round's model is the base with these.
    pub with: Vec<(Effect, f64)>,
    /// The round run on the base model with every other applied effect.
    pub round: Round,
    /// χ² of the model as it stood when the revisit began.
    pub chi2_before: f64,
    /// Its correction fitted the data better than that (lower χ²), so it took the
    /// revisited effect's place.
    pub replaced: bool,
}

/// Rounds add effects one at a time, so an earlier round fits its effect with the later ones
/// missing and may choose one that absorbs part of them (a damping that also bends the omni
/// curve that stronger side walls bend). Each applied effect but the last is searched for
/// again, as a full round on `base` with every other applied effect; its correction replaces
/// the revisited effect where it lowers χ² of the model as it stands. If one was replaced,
/// the last effect is then searched for again too. One pass; rounds labelled from `label`.
pub(super) fn revisit(
    predictor: &mut Predictor,
    base: &Config,
    applied: &mut [(Effect, f64)],
    mut current: (Config, Vec<Prediction>),
    label: usize,
    revisits: &mut Vec<Revisit>,
) -> Result<(Config, Vec<Prediction>), String> {
    let n = applied.len();
    if n < 2 {
        return Ok(current);
    }
    let mut changed = false;
    for j in 0..n {
        if j == n - 1 && !changed {
            break;
        }
        let others: Vec<(Effect, f64)> = (0..n).filter(|&k| k != j).map(|k| applied[k]).collect();
        let config = others
            .iter()
            .fold(base.clone(), |c, (e, f)| e.apply(&c, *f));
        let what = format!("revisit of {}", applied[j].0.name());
        (predictor.progress)(&format!("round {}: {what}", label + revisits.len()));
        let predictions = predictor
            .predict(std::slice::from_ref(&config), &what)?
            .remove(0);
        let now = Current {
            config: &config,
            predictions: &predictions,
        };
        let (round, kept) = search_round(predictor, &now, &others, label + revisits.len())?;
        let chi2_now = gap(predictor.measured, &current.1).chi2;
        // A revisit replaces one effect by one: a pair it names is reported, not applied.
        let better = kept
            .filter(|after| gap(predictor.measured, after).chi2 < chi2_now)
            .filter(|_| round.applied_partner.is_none());
        let was = applied[j];
        let replaced = better.is_some();
        if let (Some(after), Some((effect, factor))) = (better, round.applied) {
            applied[j] = (effect, factor);
            current = (effect.apply(&config, factor), after);
            changed = true;
        }
        revisits.push(Revisit {
            of: j,
            was,
            with: others,
            round,
            chi2_before: chi2_now,
            replaced,
        });
    }
    Ok(current)
}
