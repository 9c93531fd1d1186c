//! The calibration loop: measure the gap of the model; if it exceeds the noise, screen every
//! effect at the ends of its plausible range, refine the best candidates' 1-D fits, name the
//! effect that explains the gap (or say that none does, or that several do equally well),
//! apply it, re-simulate, and repeat while a gap beyond noise remains.

use super::attribution::{
    attribute, detection_limit, Decision, DetectionLimit, EffectFit, Grid, SingleObservable,
};
use super::effects::Effect;
use super::gap::{gap, targets, Gap, Prediction};
use super::measured::{Geometry, MeasuredSet};
use super::outside::{outside_library, single_observable, OutsideLibrary};
use super::simulate::{
    compression_config, run_all, sticking_config, Output, Run, RunCache, STICKING_TOLERANCE,
};
use crate::config::Config;

/// How much simulation a calibration may spend.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// RBD sample seeds: every compression curve is simulated once per seed.
    pub seeds: Vec<u64>,
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
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            seeds: vec![1, 2, 3],
            threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
            max_rounds: 2,
            candidates: 3,
            refinements: 3,
            refine_tolerance: 0.05,
            widenings: 4,
            effects: Effect::ALL.to_vec(),
        }
    }
}

/// One pass of the loop.
#[derive(Clone, Debug)]
pub struct Round {
    pub gap_before: Gap,
    /// Per effect, the smallest factors these data would have shown (from the screen).
    pub detection: Vec<DetectionLimit>,
    /// Set when the gap rests on one curve alone.
    pub single: Option<SingleObservable>,
    /// Set when the cause may lie outside the library (ties, bounds, a gap left).
    pub outside: Option<OutsideLibrary>,
    /// Fits sorted by χ², best first (empty when the gap was within noise).
    pub fits: Vec<EffectFit>,
    pub decision: Decision,
    /// The effect applied and its factor, with the re-simulated gap.
    pub applied: Option<(Effect, f64)>,
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
    pub baseline: Vec<Prediction>,
    pub final_predictions: Vec<Prediction>,
    pub runs: usize,
}

impl Calibration {
    pub fn baseline_gap(&self) -> &Gap {
        &self.rounds[0].gap_before
    }

    /// The gap of the corrected model.
    pub fn final_gap(&self) -> Gap {
        gap(&self.measured, &self.final_predictions)
    }

    /// The effects named (clearly ahead and predicting every curve), round by round.
    pub fn named(&self) -> Vec<Effect> {
        self.rounds
            .iter()
            .filter_map(|r| match (&r.decision, r.rejected) {
                (Decision::Named(e), false) => Some(*e),
                _ => None,
            })
            .collect()
    }
}

/// Predicts every measured curve for each config (all runs in one parallel batch).
pub struct Predictor<'a> {
    pub measured: &'a MeasuredSet,
    pub cache: &'a RunCache,
    pub settings: &'a Settings,
    pub progress: &'a (dyn Fn(&str) + Sync),
    pub runs: usize,
}

impl Predictor<'_> {
    fn runs_for(&self, config: &Config) -> Vec<Run> {
        let mut runs = Vec::new();
        for c in &self.measured.compression {
            let (_, p_max) = c.pressure_range();
            for &seed in &self.settings.seeds {
                runs.push(Run::Compression(compression_config(
                    config, c.geometry, seed, p_max,
                )));
            }
        }
        if !self.measured.sticking.is_empty() {
            runs.push(Run::Sticking(sticking_config(config)));
        }
        runs
    }

    pub fn predict(
        &mut self,
        configs: &[Config],
        what: &str,
    ) -> Result<Vec<Vec<Prediction>>, String> {
        let per: Vec<Vec<Run>> = configs.iter().map(|c| self.runs_for(c)).collect();
        let flat: Vec<Run> = per.iter().flatten().cloned().collect();
        (self.progress)(&format!(
            "{what}: {} configuration(s), {} run(s)",
            configs.len(),
            flat.len()
        ));
        let progress = self.progress;
        let step = (flat.len() / 10).max(1);
        let outputs = run_all(&flat, self.cache, self.settings.threads, &|k, n| {
            if k % step == 0 || k == n {
                progress(&format!("  {what}: {k}/{n} runs done"));
            }
        });
        self.runs += flat.len();
        let failed = outputs
            .iter()
            .filter(|o| matches!(o, Ok(Output::Envelope(e)) if e.failure.is_some()))
            .count();
        if failed > 0 {
            (self.progress)(&format!(
                "  {what}: {failed} compression(s) stopped by a run-time guard; their curves end there"
            ));
        }
        let targets = targets(self.measured);
        let mut outputs = outputs.into_iter();
        let mut all = Vec::new();
        for _ in configs {
            let mut predictions = Vec::new();
            for t in &targets {
                let mut per_seed = Vec::new();
                for _ in &self.settings.seeds {
                    match outputs.next().expect("one output per run")? {
                        Output::Envelope(e) => {
                            per_seed.push(t.iter().map(|&p| e.phi_at(p)).collect::<Vec<_>>())
                        }
                        Output::Sticking(_) => unreachable!("run order"),
                    }
                }
                predictions.push(Prediction::from_seeds(&per_seed));
            }
            if !self.measured.sticking.is_empty() {
                let Output::Sticking(v) = outputs.next().expect("one output per run")? else {
                    unreachable!("run order")
                };
                for _ in &self.measured.sticking {
                    predictions.push(Prediction::Sticking {
                        velocity: v,
                        resolution: 0.5 * STICKING_TOLERANCE * v,
                    });
                }
            }
            all.push(predictions);
        }
        Ok(all)
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
    if settings.seeds.is_empty() {
        return Err("calibration needs at least one sample seed".into());
    }
    let mut predictor = Predictor {
        measured,
        cache,
        settings,
        progress,
        runs: 0,
    };
    let has_omni = measured
        .compression
        .iter()
        .any(|c| c.geometry == Geometry::Omni);
    let mut current = base.clone();
    let mut current_predictions = predictor
        .predict(std::slice::from_ref(&current), "baseline")?
        .remove(0);
    let baseline = current_predictions.clone();
    let mut applied: Vec<(Effect, f64)> = Vec::new();
    let mut rounds = Vec::new();
    for round in 1..=settings.max_rounds.max(1) {
        let before = gap(measured, &current_predictions);
        progress(&format!(
            "round {round}: chi2 = {:.2} over {} curve(s), noise threshold {:.2}",
            before.chi2,
            before.curves.len(),
            before.threshold
        ));
        let effects: Vec<Effect> = settings
            .effects
            .iter()
            .copied()
            .filter(|e| {
                e.applies(&current, has_omni)
                    && !applied.iter().any(|(a, _)| a.family() == e.family())
            })
            .collect();
        // The screen runs even when the gap is within noise: it gives the detection limits.
        let mut grids = screen(
            &mut predictor,
            &current,
            &current_predictions,
            &effects,
            round,
        )?;
        let detection: Vec<DetectionLimit> = grids
            .iter()
            .filter_map(|g| detection_limit(measured, g))
            .collect();
        if before.within_noise() {
            progress(&format!(
                "round {round}: the gap is within sample-to-sample and measurement noise"
            ));
            for d in &detection {
                progress(&format!("round {round}: {}", describe_limit(d)));
            }
            rounds.push(Round {
                gap_before: before,
                detection,
                single: None,
                outside: None,
                fits: Vec::new(),
                decision: Decision::WithinNoise,
                applied: None,
                gap_after: None,
                rejected: false,
            });
            break;
        }
        refine(&mut predictor, &current, &mut grids, round)?;
        let single = single_observable(measured, &before, &grids);
        let (fits, decision) = attribute(measured, &before, &grids);
        let outside = outside_library(&before, &fits, &decision, !measured.compression.is_empty());
        report_fits(progress, round, &fits, &decision);
        let Some(effect) = decision.chosen() else {
            rounds.push(Round {
                gap_before: before,
                detection,
                single,
                outside,
                fits,
                decision,
                applied: None,
                gap_after: None,
                rejected: false,
            });
            break;
        };
        let factor = fits
            .iter()
            .find(|f| f.effect == effect)
            .expect("fitted")
            .factor;
        let corrected = effect.apply(&current, factor);
        let after_predictions = predictor
            .predict(
                std::slice::from_ref(&corrected),
                &format!("round {round}: re-run with {}", effect.name()),
            )?
            .remove(0);
        let after = gap(measured, &after_predictions);
        let rejected = after.chi2 >= before.chi2;
        progress(&format!(
            "round {round}: re-simulated with {} x{:.3}: chi2 {:.2} -> {:.2}{}",
            effect.name(),
            factor,
            before.chi2,
            after.chi2,
            if rejected { " (not kept)" } else { "" }
        ));
        let undetermined = matches!(decision, Decision::Undetermined(_));
        rounds.push(Round {
            gap_before: before,
            detection,
            single,
            outside,
            fits,
            decision,
            applied: Some((effect, factor)),
            gap_after: Some(after.clone()),
            rejected,
        });
        if rejected {
            break;
        }
        applied.push((effect, factor));
        current = corrected;
        current_predictions = after_predictions;
        // With several equally good explanations a further round would build on a guess.
        if undetermined || after.within_noise() {
            break;
        }
    }
    Ok(Calibration {
        measured: measured.clone(),
        settings: settings.clone(),
        base: base.clone(),
        corrected: current,
        applied,
        rounds,
        baseline,
        final_predictions: current_predictions,
        runs: predictor.runs,
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
    if settings.seeds.is_empty() {
        return Err("calibration needs at least one sample seed".into());
    }
    let mut predictor = Predictor {
        measured,
        cache,
        settings,
        progress,
        runs: 0,
    };
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
    let grids = screen(&mut predictor, base, &baseline, &effects, 1)?;
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
        runs: predictor.runs,
    })
}

/// Simulates every effect at the ends of its range (and the damping form switch at its
/// factor 1, which is not the config's model).
fn screen(
    predictor: &mut Predictor,
    current: &Config,
    current_predictions: &[Prediction],
    effects: &[Effect],
    round: usize,
) -> Result<Vec<Grid>, String> {
    let mut grids: Vec<Grid> = effects.iter().map(|&e| Grid::new(e)).collect();
    let mut points = Vec::new();
    for g in &mut grids {
        if g.effect.identity_at_one() {
            g.insert(0.0, current_predictions.to_vec());
        } else {
            points.push((g.effect, 1.0));
        }
        let (lo, hi) = g.effect.range();
        points.push((g.effect, lo));
        points.push((g.effect, hi));
    }
    add_points(predictor, &mut grids, &points, current, round, "screen")?;
    Ok(grids)
}

/// Widens the search of every effect whose fit lands on an end of its searched range with χ²
/// still falling there (see [`Grid::end_still_falling`]), towards the
/// effect's limits; then refines the best candidates' fits by a point at the interpolated
/// minimum until it stops moving. Every effect is widened, not just the best screened: an
/// effect that needs a factor far beyond the screen (the viscous damping that Poppe et al.'s
/// sticking speed needs from the paper's kappa) looks useless at the screen's ends.
fn refine(
    predictor: &mut Predictor,
    current: &Config,
    grids: &mut [Grid],
    round: usize,
) -> Result<(), String> {
    let settings = predictor.settings;
    let measured = predictor.measured;
    for pass in 1..=settings.widenings {
        let wanted: Vec<(Effect, f64)> = grids
            .iter()
            .filter(|g| g.end_still_falling(measured))
            .filter_map(|g| g.widen_point(measured).map(|u| (g.effect, u.exp())))
            .collect();
        if wanted.is_empty() {
            break;
        }
        add_points(
            predictor,
            grids,
            &wanted,
            current,
            round,
            &format!("widen {pass}"),
        )?;
    }
    let mut ranked: Vec<(f64, usize)> = grids
        .iter()
        .enumerate()
        .map(|(k, g)| (g.minimum(measured).1, k))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    let candidates: Vec<usize> = ranked
        .iter()
        .take(settings.candidates)
        .map(|&(_, k)| k)
        .collect();
    for pass in 1..=settings.refinements {
        // A minimum on an end is a bound: nothing to refine there.
        let wanted: Vec<(Effect, f64)> = candidates
            .iter()
            .map(|&k| &grids[k])
            .filter(|g| g.minimum_at_end(measured).is_none())
            .filter_map(|g| {
                g.next_point(measured, settings.refine_tolerance)
                    .map(|u| (g.effect, u.exp()))
            })
            .collect();
        if wanted.is_empty() {
            break;
        }
        add_points(
            predictor,
            grids,
            &wanted,
            current,
            round,
            &format!("refine {pass}"),
        )?;
    }
    Ok(())
}

fn add_points(
    predictor: &mut Predictor,
    grids: &mut [Grid],
    points: &[(Effect, f64)],
    current: &Config,
    round: usize,
    what: &str,
) -> Result<(), String> {
    let configs: Vec<Config> = points.iter().map(|&(e, f)| e.apply(current, f)).collect();
    let predictions = predictor.predict(&configs, &format!("round {round}: {what}"))?;
    for (&(effect, factor), p) in points.iter().zip(predictions) {
        let grid = grids
            .iter_mut()
            .find(|g| g.effect == effect)
            .expect("grid per effect");
        grid.insert(factor.ln(), p);
    }
    Ok(())
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
        Decision::Unpredictive { effect, fails } => format!(
            "no effect explains all curves: {} fits them jointly, but fitted without {} it does \
             not predict {}; applied as the best partial explanation",
            effect.name(),
            fails.join(", "),
            if fails.len() == 1 { "it" } else { "them" }
        ),
        Decision::Undetermined(tied) => format!(
            "undetermined: {} explain the data equally well; more or different data are needed \
             to tell them apart",
            tied.iter().map(|e| e.name()).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// "x0.42", or "beyond x0.125" when the searched range holds no detectable factor.
pub fn limit_text(limit: Option<f64>, end: f64) -> String {
    match limit {
        Some(f) => format!("x{}", short_factor(f)),
        None => format!("not within x{}", short_factor(end)),
    }
}

fn short_factor(f: f64) -> String {
    if (0.01..1000.0).contains(&f) {
        format!("{f:.3}")
    } else {
        format!("{f:.2e}")
    }
}

/// One line per effect: the smallest factors the data would have shown, each way.
pub fn describe_limit(d: &DetectionLimit) -> String {
    format!(
        "{}: shown below {} or above {} (with 4x the samples: {} / {}; with the measured \
         sigma halved: {} / {})",
        d.effect.name(),
        limit_text(d.lower, d.searched.0),
        limit_text(d.upper, d.searched.1),
        limit_text(d.lower_4x_samples, d.searched.0),
        limit_text(d.upper_4x_samples, d.searched.1),
        limit_text(d.lower_half_sigma, d.searched.0),
        limit_text(d.upper_half_sigma, d.searched.1),
    )
}
