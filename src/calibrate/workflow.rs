//! The calibration loop: measure the gap of the model; if it exceeds the noise, screen every
//! effect at the ends of its plausible range, refine the best candidates' 1-D fits, name the
//! effect that explains the gap (or say that none does, or that several do equally well),
//! apply it, re-simulate, and repeat while a gap beyond noise remains.

use super::attribution::{detection_limit, Decision, DetectionLimit};
pub use super::detection::limit_text;
use super::effects::Effect;
use super::gap::{gap, Gap, Prediction};
use super::measured::{Geometry, MeasuredSet};
use super::predictor::{Cost, Predictor};
use super::revisit::revisit;
pub use super::revisit::Revisit;
use super::round::search_round;
pub use super::round::{describe_decision, describe_limit, Round};
use super::search::{screen, Current};
use super::simulate::RunCache;
use crate::config::Config;

/// How much simulation a calibration may spend.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// RBD sample seeds: every compression curve is simulated once per seed for the baseline
    /// and for each correction a round keeps.
    pub seeds: Vec<u64>,
    /// Seeds of the screen, the widening and the refinement: the first this many of `seeds`,
    /// on common random numbers (see [`super::predictor`]); 0 screens on every seed.
    pub screen_seeds: usize,
    /// Sample size of a first screen that only drops effects (multi-fidelity in size; 0:
    /// none). Everything else, the detection limits of the effects it keeps included, is at
    /// the config's size ([`super::search::screen_by_size`]).
    pub screen_monomers: usize,
    /// Drop the effects that cannot come within Δχ² = 2 of the best one after the screen
    /// ([`super::search::pruned`]) instead of widening and refining them too.
    pub prune: bool,
    /// Screen at both ends of each effect's range (the default) instead of the upper end
    /// only: an effect is then pruned only on runs on both sides of its factor 1.
    pub both_ends: bool,
    /// Fit pairs of effects jointly and let them into the decision ([`super::pairs`]), and
    /// propose the measurement that separates an undetermined result's leading explanations
    /// ([`super::discriminate`]). Off: the single-effect search the older committed
    /// calibrations were made with.
    pub pairs: bool,
    pub threads: usize,
    /// Effects added one after the other at most.
    pub max_rounds: usize,
    /// Effects whose fits are refined beyond the screen, per round (best screened first).
    pub candidates: usize,
    /// Refinement passes per round (one simulated point per candidate each).
    pub refinements: usize,
    /// A refinement stops when the interpolated minimum is within this of a simulated factor
    /// (in ln factor; 0.05 is 5%).
    pub refine_tolerance: f64,
    /// Widenings per candidate at most when its fit lands on an end of the searched range
    /// (each doubles the distance of that end from the factor 1 in ln factor).
    pub widenings: usize,
    pub effects: Vec<Effect>,
    /// After the rounds, search again for each applied effect with the later ones in
    /// ([`revisit`]).
    pub revisit: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            seeds: vec![1, 2, 3],
            screen_seeds: 1,
            screen_monomers: 0,
            prune: true,
            both_ends: true,
            pairs: true,
            threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
            max_rounds: 2,
            candidates: 3,
            refinements: 3,
            refine_tolerance: 0.05,
            widenings: 4,
            effects: Effect::ALL.to_vec(),
            revisit: false,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Calibration {
    pub measured: MeasuredSet,
    pub settings: Settings,
    pub base: Config,
    pub corrected: Config,
    /// Effects applied, in order, with their factors.
    pub applied: Vec<(Effect, f64)>,
    pub rounds: Vec<Round>,
    /// The earlier rounds searched again with the later effects in (`Settings::revisit`).
    pub revisits: Vec<Revisit>,
    pub baseline: Vec<Prediction>,
    pub final_predictions: Vec<Prediction>,
    pub runs: usize,
    pub cost: Cost,
}

impl Calibration {
    pub fn baseline_gap(&self) -> &Gap {
        &self.rounds[0].gap_before
    }

    /// The gap of the corrected model.
    pub fn final_gap(&self) -> Gap {
        gap(&self.measured, &self.final_predictions)
    }

    /// The effects named (clearly ahead and predicting every curve), round by round, then
    /// those a revisit named for the place it revisited.
    pub fn named(&self) -> Vec<Effect> {
        let standing = |r: &&Revisit| r.round.decision.chosen() == Some(self.applied[r.of].0);
        self.rounds
            .iter()
            .chain(self.revisits.iter().filter(standing).map(|r| &r.round))
            .flat_map(|r| match (&r.decision, r.rejected) {
                (Decision::Named(e), false) => vec![*e],
                (Decision::NamedPair(p), false) => p.to_vec(),
                _ => Vec::new(),
            })
            .collect()
    }
}

/// Calibrates `base` against `measured`.
pub fn calibrate(
    measured: &MeasuredSet,
    base: &Config,
    settings: &Settings,
    cache: &RunCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Calibration, String> {
    check_settings(settings, base)?;
    let mut predictor = Predictor::new(measured, cache, settings, progress);
    let mut current = base.clone();
    let mut current_predictions = predictor
        .predict(std::slice::from_ref(&current), "baseline")?
        .remove(0);
    let baseline = current_predictions.clone();
    let mut applied: Vec<(Effect, f64)> = Vec::new();
    let mut rounds = Vec::new();
    for round in 1..=settings.max_rounds.max(1) {
        let now = Current {
            config: &current,
            predictions: &current_predictions,
        };
        let (r, kept) = search_round(&mut predictor, &now, &applied, round)?;
        let undetermined = r.decision.is_undetermined();
        let (applied_now, within) = (r.applied, r.gap_after.as_ref().map(Gap::within_noise));
        let partner = r.applied_partner;
        rounds.push(r);
        let (Some((effect, factor)), Some(after)) = (applied_now, kept) else {
            break;
        };
        for (e, f) in std::iter::once((effect, factor)).chain(partner) {
            applied.push((e, f));
            current = e.apply(&current, f);
        }
        current_predictions = after;
        // With several equally good explanations a further round would build on a guess.
        if undetermined || within == Some(true) {
            break;
        }
    }
    let mut revisits = Vec::new();
    if settings.revisit {
        let last = (current, current_predictions);
        let label = rounds.len() + 1;
        (current, current_predictions) = revisit(
            &mut predictor,
            base,
            &mut applied,
            last,
            label,
            &mut revisits,
        )?;
    }
    Ok(Calibration {
        measured: measured.clone(),
        settings: settings.clone(),
        base: base.clone(),
        corrected: current,
        applied,
        rounds,
        revisits,
        baseline,
        final_predictions: current_predictions,
        runs: predictor.cost.runs(),
        cost: predictor.cost,
    })
}

/// What a planned data set and system size can resolve: the detection limits from the
/// baseline and the screen alone (no fit).
#[derive(Clone, Debug)]
pub struct Plan {
    pub measured: MeasuredSet,
    pub settings: Settings,
    pub base: Config,
    pub baseline: Gap,
    pub detection: Vec<DetectionLimit>,
    pub runs: usize,
}

/// `dustdem calibrate --plan`: the baseline and the screen of every effect, and the detection
/// limits they give. The measured φ values do not enter the limits (only the pressures, the
/// uncertainties and which curves there are), so a planned file may hold any values.
pub fn plan(
    measured: &MeasuredSet,
    base: &Config,
    settings: &Settings,
    cache: &RunCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Plan, String> {
    check_seeds(settings)?;
    let mut predictor = Predictor::new(measured, cache, settings, progress);
    let has_omni = measured
        .compression
        .iter()
        .any(|c| c.geometry == Geometry::Omni);
    let baseline = predictor
        .predict(std::slice::from_ref(base), "baseline")?
        .remove(0);
    let effects: Vec<Effect> = settings
        .effects
        .iter()
        .copied()
        .filter(|e| e.applies(base, has_omni))
        .collect();
    let now = Current {
        config: base,
        predictions: &baseline,
    };
    let grids = screen(&mut predictor, &now, &effects, 1)?;
    let detection: Vec<DetectionLimit> = grids
        .iter()
        .filter_map(|g| detection_limit(measured, g))
        .collect();
    for d in &detection {
        progress(&format!("plan: {}", describe_limit(d)));
    }
    Ok(Plan {
        measured: measured.clone(),
        settings: settings.clone(),
        base: base.clone(),
        baseline: gap(measured, &baseline),
        detection,
        runs: predictor.cost.runs(),
    })
}

fn check_settings(settings: &Settings, base: &Config) -> Result<(), String> {
    let (m, n) = (settings.screen_monomers, base.sample.monomers);
    if m > n {
        return Err(format!(
            "screen monomers: {m} is more than the config's [sample] monomers ({n}); allowed 0 \
             (the config's size) to {n}"
        ));
    }
    check_seeds(settings)
}

fn check_seeds(settings: &Settings) -> Result<(), String> {
    let n = settings.seeds.len();
    if n == 0 {
        return Err("calibration needs at least one sample seed".into());
    }
    if settings.screen_seeds > n {
        return Err(format!(
            "screen seeds: {} is more than the {n} seed(s) given; allowed 0 (every seed) to {n}",
            settings.screen_seeds
        ));
    }
    Ok(())
}
