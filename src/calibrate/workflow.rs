//! The calibration loop: measure the gap of the model; if it exceeds the noise, screen every
//! effect at the ends of its plausible range, refine the best candidates' 1-D fits, name the
//! effect that explains the gap (or say that none does, or that several do equally well),
//! apply it, re-simulate, and repeat while a gap beyond noise remains.

use super::attribution::{detection_limit, Decision, DetectionLimit, EffectFit, SingleObservable};
pub use super::detection::limit_text;
use super::effects::Effect;
use super::gap::{gap, Gap, Prediction};
use super::grid::Grid;
use super::leaders::{confirm_pairs, polish_leaders};
use super::discriminate::{discriminate, leading_explanations, Discrimination};
use super::pairs::{fit_pairs, PairFit};
use super::measured::{Geometry, MeasuredSet};
use super::outside::{outside_library, single_observable, OutsideLibrary};
use super::predictor::{Cost, Predictor};
use super::revisit::revisit;
pub use super::revisit::Revisit;
use super::search::{pruned, refine, report_ranking, screen, screen_by_size, Current};
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

/// One pass of the loop.
#[derive(Clone, Debug)]
pub struct Round {
    pub gap_before: Gap,
    /// Per effect, the smallest factors these data would have shown (from the screen).
    pub detection: Vec<DetectionLimit>,
    /// With a screen on a smaller sample: its size and the effects it dropped (their
    /// detection limits come from it; every other effect's from the target size).
    pub size_screened: Option<(usize, Vec<Effect>)>,
    /// Set when the gap rests on one curve alone.
    pub single: Option<SingleObservable>,
    /// Set when the cause may lie outside the library (ties, bounds, a gap left).
    pub outside: Option<OutsideLibrary>,
    /// Effects dropped after the screen: no scaling of their screened response came within
    /// Δχ² = 2 of the best effect, so they were neither widened nor refined.
    pub pruned: Vec<Effect>,
    /// Fits sorted by χ², best first (empty when the gap was within noise).
    pub fits: Vec<EffectFit>,
    /// Every pair of effects of two families fitted jointly, best first
    /// ([`super::pairs`]); the ones the decision rests on simulated.
    pub pairs: Vec<PairFit>,
    pub decision: Decision,
    /// The effect applied and its factor, with the re-simulated gap.
    pub applied: Option<(Effect, f64)>,
    /// The second effect applied with it when the round chose a pair.
    pub applied_partner: Option<(Effect, f64)>,
    /// For an undetermined decision: the measurements that would tell its two leading
    /// explanations apart, best first.
    pub discrimination: Option<Discrimination>,
    pub gap_after: Option<Gap>,
    /// The correction did not lower χ² when re-simulated, so it was not kept.
    pub rejected: bool,
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

/// One round on the model `now`, whose applied effects (`applied`: their families are not
/// searched again) it builds on: the screen, the fits, the decision, and the chosen effect
/// re-simulated. Returns the round and, when its correction lowered χ², the corrected
/// model's predictions.
pub(super) fn search_round(
    predictor: &mut Predictor,
    now: &Current,
    applied: &[(Effect, f64)],
    round: usize,
) -> Result<(Round, Option<Vec<Prediction>>), String> {
    let (measured, settings, progress) =
        (predictor.measured, predictor.settings, predictor.progress);
    let before = gap(measured, now.predictions);
    progress(&format!(
        "round {round}: chi2 = {:.2} over {} curve(s), noise threshold {:.2}",
        before.chi2,
        before.curves.len(),
        before.threshold
    ));
    let (mut grids, detection, size_screened, small_dropped) =
        screen_round(predictor, now, applied, &before, round)?;
    let mut r = Round {
        gap_before: before.clone(),
        detection,
        size_screened: None,
        single: None,
        outside: None,
        pruned: Vec::new(),
        fits: Vec::new(),
        pairs: Vec::new(),
        decision: Decision::WithinNoise,
        applied: None,
        applied_partner: None,
        discrimination: None,
        gap_after: None,
        rejected: false,
    };
    if before.within_noise() {
        progress(&format!(
            "round {round}: the gap is within sample-to-sample and measurement noise"
        ));
        for d in &r.detection {
            progress(&format!("round {round}: {}", describe_limit(d)));
        }
        return Ok((r, None));
    }
    r.size_screened = size_screened;
    r.pruned = if settings.prune {
        pruned(measured, &grids, now.predictions)
    } else {
        Vec::new()
    };
    if !r.pruned.is_empty() {
        progress(&format!(
            "round {round}: not widened or refined (cannot come within chi2 + 2 of the \
             best): {}",
            names(&r.pruned)
        ));
    }
    refine(predictor, now, &mut grids, &r.pruned, round)?;
    let (fits, single_decision, polished) =
        polish_leaders(predictor, now, &mut grids, &before, round)?;
    // An effect that explains little alone can be half of a pair: the pairs are fitted over
    // every screened effect, those the smaller screen dropped included (their responses on
    // the smaller samples, added to the current model like the others'); only simulated pairs
    // enter the decision.
    let (decision, pairs, simulated_pairs) = if settings.pairs {
        let all_grids: Vec<Grid> = grids.iter().chain(&small_dropped).cloned().collect();
        let pairs = fit_pairs(measured, &all_grids, now.predictions, &fits, &r.detection);
        confirm_pairs(predictor, now, &fits, pairs, single_decision, round)?
    } else {
        (single_decision, Vec::new(), Vec::new())
    };
    r.single = single_observable(measured, &before, &grids);
    r.outside = outside_library(&before, &fits, &decision, !measured.compression.is_empty());
    report_fits(progress, round, &fits, &decision);
    report_pairs(progress, round, &pairs);
    let kept: Option<(Vec<(Effect, f64)>, Vec<Prediction>)> = match decision.chosen_pair() {
        Some(pair) => simulated_pairs
            .into_iter()
            .filter(|(both, _)| both.map(|b| b.0) == pair)
            .min_by(|a, b| gap(measured, &a.1).chi2.total_cmp(&gap(measured, &b.1).chi2))
            .map(|(both, p)| (both.to_vec(), p)),
        None => decision
            .chosen()
            .and_then(|e| polished.into_iter().find(|p| p.0 == e))
            .map(|(e, f, p)| (vec![(e, f)], p)),
    };
    let two = leading_explanations(&decision, &fits, &pairs, now.config);
    if let Some(two) = two.filter(|_| settings.pairs) {
        let d = discriminate(measured, two, settings, predictor.cache, progress)?;
        if let Some(best) = d.proposals.first() {
            progress(&format!(
                "round {round}: {} or {}: {} would separate them by chi2 {:.2}",
                d.between[0], d.between[1], best.what, best.separation
            ));
        }
        r.discrimination = Some(d);
    }
    (r.fits, r.pairs, r.decision) = (fits, pairs, decision);
    let Some((chosen, after_predictions)) = kept else {
        return Ok((r, None));
    };
    let after = gap(measured, &after_predictions);
    r.rejected = after.chi2 >= before.chi2;
    let text: Vec<String> = chosen
        .iter()
        .map(|(e, f)| format!("{} x{f:.3}", e.name()))
        .collect();
    progress(&format!(
        "round {round}: re-simulated with {}: chi2 {:.2} -> {:.2}{}",
        text.join(" and "),
        before.chi2,
        after.chi2,
        if r.rejected { " (not kept)" } else { "" }
    ));
    (r.applied, r.applied_partner) = (Some(chosen[0]), chosen.get(1).copied());
    r.gap_after = Some(after);
    Ok(match r.rejected {
        true => (r, None),
        false => (r, Some(after_predictions)),
    })
}

/// A round's screen: every effect not of an applied effect's family, on a smaller sample
/// first where asked (and the gap is beyond noise), with the detection limits it gives.
/// Returns the grids screened at the target size, the limits, what the smaller screen
/// dropped, and the grids it dropped.
#[allow(clippy::type_complexity)]
fn screen_round(
    predictor: &mut Predictor,
    now: &Current,
    applied: &[(Effect, f64)],
    before: &Gap,
    round: usize,
) -> Result<
    (
        Vec<Grid>,
        Vec<DetectionLimit>,
        Option<(usize, Vec<Effect>)>,
        Vec<Grid>,
    ),
    String,
> {
    let (measured, settings, progress) =
        (predictor.measured, predictor.settings, predictor.progress);
    let has_omni = measured
        .compression
        .iter()
        .any(|c| c.geometry == Geometry::Omni);
    let effects: Vec<Effect> = settings
        .effects
        .iter()
        .copied()
        .filter(|e| {
            e.applies(now.config, has_omni)
                && !applied.iter().any(|(a, _)| a.family() == e.family())
        })
        .collect();
    // The screen runs even when the gap is within noise: it gives the detection limits,
    // which are then all the round gives, so it runs at the target size.
    // A sticking velocity does not depend on the sample: nothing to screen smaller.
    let smaller = (1..now.config.sample.monomers).contains(&settings.screen_monomers)
        && !measured.compression.is_empty();
    let (grids, small) = match !before.within_noise() && smaller {
        true => screen_by_size(predictor, now, &effects, round)?,
        false => (screen(predictor, now, &effects, round)?, Vec::new()),
    };
    report_ranking(
        progress,
        &format!("round {round}: screen ranking"),
        measured,
        &grids,
    );
    let detection: Vec<DetectionLimit> = grids
        .iter()
        .chain(&small)
        .filter_map(|g| detection_limit(measured, g))
        .collect();
    let size_screened = (!small.is_empty()).then(|| {
        let dropped: Vec<Effect> = small.iter().map(|g| g.effect).collect();
        progress(&format!(
            "round {round}: dropped by the {}-monomer screen: {}",
            settings.screen_monomers,
            names(&dropped)
        ));
        (settings.screen_monomers, dropped)
    });
    Ok((grids, detection, size_screened, small))
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

fn names(effects: &[Effect]) -> String {
    effects
        .iter()
        .map(|e| e.name())
        .collect::<Vec<_>>()
        .join(", ")
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

/// The pairs that need both their effects, one line each.
fn report_pairs(progress: &dyn Fn(&str), round: usize, pairs: &[PairFit]) {
    for p in pairs.iter().filter(|p| p.needs_both()).take(5) {
        let simulated = p
            .simulated_chi2
            .map_or(String::new(), |c| format!(", simulated {c:.2}"));
        progress(&format!(
            "round {round}: pair {} chi2 {:.2}{simulated}",
            p.label(),
            p.chi2
        ));
    }
}

fn report_fits(progress: &dyn Fn(&str), round: usize, fits: &[EffectFit], decision: &Decision) {
    for f in fits {
        progress(&format!("round {round}: {}", f.summary()));
    }
    progress(&format!("round {round}: {}", describe_decision(decision)));
}

/// One sentence for a decision.
pub fn describe_decision(d: &Decision) -> String {
    match d {
        Decision::WithinNoise => {
            "the gap is within sample-to-sample and measurement noise: no effect is named".into()
        }
        Decision::NoEffectExplains => {
            "no single effect lowers the gap significantly: no effect is named".into()
        }
        Decision::Named(e) => format!("named: {}", e.name()),
        Decision::NamedPair(p) => format!(
            "named: the pair {} + {} (both needed; no single effect or other pair comes near)",
            p[0].name(),
            p[1].name()
        ),
        Decision::Unpredictive { effect, fails } => format!(
            "no effect explains all curves: {} fits them jointly, but fitted without {} it does \
             not predict {}; applied as the best partial explanation",
            effect.name(),
            fails.join(", "),
            if fails.len() == 1 { "it" } else { "them" }
        ),
        Decision::Undetermined { singles, pairs } => format!(
            "undetermined: {} explain the data equally well; more or different data are needed \
             to tell them apart",
            singles
                .iter()
                .map(|e| e.name().to_string())
                .chain(pairs.iter().map(|p| format!("{} + {}", p[0].name(), p[1].name())))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// One line per effect: the smallest factors the data would have shown, each way.
pub fn describe_limit(d: &DetectionLimit) -> String {
    let t = d.texts();
    format!(
        "{}: shown below {} or above {} (with 4x the samples: {} / {}; with the measured \
         sigma halved: {} / {})",
        d.effect.name(),
        t[0],
        t[1],
        t[2],
        t[3],
        t[4],
        t[5],
    )
}
