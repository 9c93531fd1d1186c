//! One round of the calibration loop: the screen, the pruning, the widening and refinement,
//! the 1-D fits, the pairs, the decision, and the chosen correction re-simulated; with the
//! progress lines and sentences that describe a round.

use super::attribution::{detection_limit, Decision, DetectionLimit, EffectFit, SingleObservable};
use super::discriminate::{discriminate, leading_explanations, Discrimination};
use super::effects::Effect;
use super::gap::{gap, Gap, Prediction};
use super::grid::Grid;
use super::leaders::{confirm_pairs, polish_leaders, PolishedPair};
use super::measured::Geometry;
use super::outside::{outside_library, single_observable, OutsideLibrary};
use super::pairs::{fit_pairs, PairFit};
use super::predictor::Predictor;
use super::search::{pruned, refine, report_ranking, screen, screen_by_size, Current};

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
    let mut r = new_round(&before, detection);
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
    r.pruned = match settings.prune {
        true => pruned(measured, &grids, now.predictions),
        false => Vec::new(),
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
    let grids_seen: Vec<Grid> = grids.iter().chain(&small_dropped).cloned().collect();
    let (decision, pairs, simulated_pairs) = with_pairs(
        predictor,
        now,
        (&grids_seen, &r.detection),
        &fits,
        single_decision,
        round,
    )?;
    r.single = single_observable(measured, &before, &grids);
    r.outside = outside_library(&before, &fits, &decision, !measured.compression.is_empty());
    report_fits(progress, round, &fits, &decision);
    report_pairs(progress, round, &pairs);
    let kept = chosen_correction(measured, &decision, polished, simulated_pairs);
    if settings.pairs {
        r.discrimination = proposal(predictor, now, &decision, &fits, &pairs, round)?;
    }
    (r.fits, r.pairs, r.decision) = (fits, pairs, decision);
    let Some((chosen, after_predictions)) = kept else {
        return Ok((r, None));
    };
    record_correction(
        &mut r,
        measured,
        &chosen,
        &after_predictions,
        progress,
        round,
    );
    Ok(match r.rejected {
        true => (r, None),
        false => (r, Some(after_predictions)),
    })
}

/// A round that has only screened: its gap and detection limits, nothing fitted or decided.
fn new_round(before: &Gap, detection: Vec<DetectionLimit>) -> Round {
    Round {
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
    }
}

/// The decision from single effects revisited with the pairs, when the settings fit them.
/// An effect that explains little alone can be half of a pair: the pairs are fitted over
/// every screened effect (`grids`, those the smaller screen dropped included: their responses
/// on the smaller samples, added to the current model like the others'), with the detection
/// limits for the pinned fits; only simulated pairs enter the decision.
fn with_pairs(
    predictor: &mut Predictor,
    now: &Current,
    (grids, detection): (&[Grid], &[DetectionLimit]),
    fits: &[EffectFit],
    single: Decision,
    round: usize,
) -> Result<(Decision, Vec<PairFit>, Vec<PolishedPair>), String> {
    if !predictor.settings.pairs {
        return Ok((single, Vec::new(), Vec::new()));
    }
    let pairs = fit_pairs(predictor.measured, grids, now.predictions, fits, detection);
    confirm_pairs(predictor, now, fits, pairs, single, round)
}

/// The round's correction as re-simulated: applied (with its partner for a pair), its gap,
/// and whether it was rejected (χ² did not fall).
fn record_correction(
    r: &mut Round,
    measured: &super::measured::MeasuredSet,
    chosen: &[(Effect, f64)],
    after_predictions: &[Prediction],
    progress: &(dyn Fn(&str) + Sync),
    round: usize,
) {
    let after = gap(measured, after_predictions);
    r.rejected = after.chi2 >= r.gap_before.chi2;
    let text: Vec<String> = chosen
        .iter()
        .map(|(e, f)| format!("{} x{f:.3}", e.name()))
        .collect();
    progress(&format!(
        "round {round}: re-simulated with {}: chi2 {:.2} -> {:.2}{}",
        text.join(" and "),
        r.gap_before.chi2,
        after.chi2,
        if r.rejected { " (not kept)" } else { "" }
    ));
    (r.applied, r.applied_partner) = (Some(chosen[0]), chosen.get(1).copied());
    r.gap_after = Some(after);
}

/// The effects a decision applies, with their factors, and their predictions on every seed:
/// a chosen pair's best simulation, or a chosen single effect's polished run.
type Correction = (Vec<(Effect, f64)>, Vec<Prediction>);

fn chosen_correction(
    measured: &super::measured::MeasuredSet,
    decision: &Decision,
    polished: Vec<super::leaders::Polished>,
    simulated_pairs: Vec<PolishedPair>,
) -> Option<Correction> {
    let chi2 = |p: &[Prediction]| gap(measured, p).chi2;
    match decision.chosen_pair() {
        Some(pair) => simulated_pairs
            .into_iter()
            .filter(|(both, _)| both.map(|b| b.0) == pair)
            .min_by(|a, b| chi2(&a.1).total_cmp(&chi2(&b.1)))
            .map(|(both, p)| (both.to_vec(), p)),
        None => decision
            .chosen()
            .and_then(|e| polished.into_iter().find(|p| p.0 == e))
            .map(|(e, f, p)| (vec![(e, f)], p)),
    }
}

/// For an undetermined decision, the measurements that would separate its two leading
/// explanations ([`discriminate`]).
fn proposal(
    predictor: &Predictor,
    now: &Current,
    decision: &Decision,
    fits: &[EffectFit],
    pairs: &[PairFit],
    round: usize,
) -> Result<Option<Discrimination>, String> {
    let Some(two) = leading_explanations(decision, fits, pairs, now.config) else {
        return Ok(None);
    };
    let (measured, settings, progress) =
        (predictor.measured, predictor.settings, predictor.progress);
    let d = discriminate(measured, two, settings, predictor.cache, progress)?;
    if let Some(best) = d.proposals.first() {
        progress(&format!(
            "round {round}: {} or {}: {} would separate them by chi2 {:.2}",
            d.between[0], d.between[1], best.what, best.separation
        ));
    }
    Ok(Some(d))
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

fn names(effects: &[Effect]) -> String {
    effects
        .iter()
        .map(|e| e.name())
        .collect::<Vec<_>>()
        .join(", ")
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
        Decision::Undetermined { singles, pairs } => {
            format!(
            "undetermined: {} explain the data equally well; more or different data are needed \
             to tell them apart",
            singles
                .iter()
                .map(|e| e.name().to_string())
                .chain(pairs.iter().map(|p| format!("{} + {}", p[0].name(), p[1].name())))
                .collect::<Vec<_>>()
                .join(", ")
        )
        }
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
