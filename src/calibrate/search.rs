//! The search of one round: screen every effect at the upper end of its range, drop the
//! effects that cannot come near the best one, widen the searched range where χ² still falls
//! at an end (below factor 1 too, where the screen did not look), and refine the best
//! candidates' minima.

use super::attribution::Grid;
use super::effects::Effect;
use super::gap::{gap, Prediction};
use super::measured::MeasuredSet;
use super::predictor::Predictor;
use crate::config::Config;

/// An effect is dropped after the screen when even its most favourable scaling of a screened
/// response stays this far (in χ²) above the best effect's minimum: it can neither win nor tie.
pub const PRUNE_DELTA_CHI2: f64 = 2.0;

/// Scalings of a screened response tried for the optimistic χ² of an effect: up to 64 times
/// the screened change, either way (a response weak at the screen's end may grow beyond it:
/// viscous damping ×500 is what Poppe et al.'s sticking speed asks of the paper's κ).
const SCALINGS: [f64; 16] = [
    0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 64.0,
];

/// The model a round starts from, with its full predictions.
pub struct Current<'a> {
    pub config: &'a Config,
    pub predictions: &'a [Prediction],
}

/// Simulates every effect at the upper end of its range (and the damping form switch at its
/// factor 1, which is not the config's model). One end, not both: the pruning scales the
/// screened change either way ([`optimistic_chi2`]), the detection limits below factor 1
/// mirror it (linear in ln factor, and say so), and an effect whose χ² rises towards the
/// upper end while it is still in the race is widened below 1 ([`Grid::widen_point`]) before
/// it is fitted. The lower ends of the effects that are dropped are never simulated.
pub fn screen(
    predictor: &mut Predictor,
    current: &Current,
    effects: &[Effect],
    round: usize,
) -> Result<Vec<Grid>, String> {
    let mut grids: Vec<Grid> = effects.iter().map(|&e| Grid::new(e)).collect();
    let mut points = Vec::new();
    for g in &mut grids {
        if g.effect.identity_at_one() {
            g.insert(0.0, current.predictions.to_vec());
        } else {
            points.push((g.effect, 1.0));
        }
        let (lo, hi) = g.effect.range();
        if predictor.settings.both_ends {
            points.push((g.effect, lo));
        }
        points.push((g.effect, hi));
    }
    add_points(predictor, &mut grids, &points, current, round, "screen")?;
    Ok(grids)
}

/// Multi-fidelity in size: every effect screened on the smaller sample (`screen_monomers`),
/// those that cannot come near the best there dropped ([`pruned_by_smaller_screen`]), the
/// rest screened again
/// at the target size, from which the round goes on as without the smaller screen. The
/// smaller sample only ranks: the fits, the polish and the kept effects' detection limits are
/// all at the target size. Returns the target-size grids of the effects kept and the
/// smaller-sample grids of those dropped.
pub fn screen_by_size(
    predictor: &mut Predictor,
    current: &Current,
    effects: &[Effect],
    round: usize,
) -> Result<(Vec<Grid>, Vec<Grid>), String> {
    let measured = predictor.measured;
    predictor.screen_monomers = predictor.settings.screen_monomers;
    let small = screen(predictor, current, effects, round)?;
    predictor.screen_monomers = 0;
    let what = format!(
        "round {round}: ranking on {} monomers",
        predictor.settings.screen_monomers
    );
    report_ranking(predictor.progress, &what, measured, &small);
    let dropped = pruned_by_smaller_screen(measured, &small, current.predictions);
    let kept: Vec<Effect> = effects
        .iter()
        .copied()
        .filter(|e| !dropped.contains(e))
        .collect();
    let grids = screen(predictor, current, &kept, round)?;
    let small_dropped = small
        .into_iter()
        .filter(|g| dropped.contains(&g.effect))
        .collect();
    Ok((grids, small_dropped))
}

/// The lowest χ² any scaling (either sign, up to ×64) of one of the grid's simulated changes
/// from the current model reaches: a bound on what the effect could do if its response kept
/// a shape the screen has seen.
pub fn optimistic_chi2(m: &MeasuredSet, grid: &Grid, current: &[Prediction]) -> f64 {
    // The scalings sample the simulated segment coarsely: a minimum between them (a narrow
    // valley of a large χ²) is the grid's own, and the leader must never prune itself.
    let mut best = gap(m, current).chi2.min(grid.minimum(m).1);
    for (_, predictions) in &grid.points {
        for &s in &SCALINGS {
            for t in [s, -s] {
                let moved: Vec<Prediction> = current
                    .iter()
                    .zip(predictions)
                    .map(|(a, b)| Prediction::blend(a, b, t))
                    .collect();
                best = best.min(gap(m, &moved).chi2);
            }
        }
    }
    best
}

/// The effects that cannot come within [`PRUNE_DELTA_CHI2`] of the best screened minimum.
pub fn pruned(m: &MeasuredSet, grids: &[Grid], current: &[Prediction]) -> Vec<Effect> {
    pruned_beyond(m, grids, current, |_| PRUNE_DELTA_CHI2)
}

/// The effects whose best possible χ² lies more than `margin(leader's χ²)` above the
/// leader's ([`best_possible_chi2`]).
fn pruned_beyond(
    m: &MeasuredSet,
    grids: &[Grid],
    current: &[Prediction],
    margin: impl Fn(f64) -> f64,
) -> Vec<Effect> {
    let leader = grids
        .iter()
        .map(|g| g.minimum(m).1)
        .fold(f64::INFINITY, f64::min);
    grids
        .iter()
        .filter(|g| best_possible_chi2(m, g, current) > leader + margin(leader))
        .map(|g| g.effect)
        .collect()
}

/// What an effect could reach, by what was simulated: with runs on both sides of factor 1
/// its fit through them, unless χ² still falls at an end the search may widen (then nothing
/// is known beyond that end, and the effect is kept); with the upper end only, the
/// optimistic scaling of its response ([`optimistic_chi2`]), which is no bound: it dropped
/// the viscous damping form at 14.6 where a run gave 2.29.
pub fn best_possible_chi2(m: &MeasuredSet, grid: &Grid, current: &[Prediction]) -> f64 {
    if grid.lower_unsearched() {
        return optimistic_chi2(m, grid, current);
    }
    if grid.end_still_falling(m) && grid.widen_point(m).is_some() {
        return f64::NEG_INFINITY;
    }
    grid.minimum(m).1
}

/// What a screen on a smaller sample drops: the effects that, even scaled optimistically,
/// explain less than half of what the best one explains there (and lie beyond
/// [`PRUNE_DELTA_CHI2`] of it). A smaller sample's response can differ from the target's in
/// shape, not only in size (which the scalings cover): at 60 of 120 monomers the side walls
/// of a second round (χ² 15.3 against the leader's 11.7 from 23.3) would have been dropped by
/// the Δχ² = 2 rule although they are what the data hide.
pub fn pruned_by_smaller_screen(
    m: &MeasuredSet,
    grids: &[Grid],
    current: &[Prediction],
) -> Vec<Effect> {
    let base = gap(m, current).chi2;
    pruned_beyond(m, grids, current, |leader| {
        PRUNE_DELTA_CHI2.max(0.5 * (base - leader))
    })
}

/// Widens the search of every effect whose fit lands on an end of its searched range with χ²
/// still falling there (see [`Grid::end_still_falling`]), towards the effect's limits; then
/// refines the best candidates' fits by a point at the interpolated minimum until it stops
/// moving. Every effect not in `dropped` is widened, not just the best screened: an effect
/// that needs a factor far beyond the screen (the viscous damping that Poppe et al.'s sticking
/// speed needs from the paper's κ) looks useless at the screen's ends.
pub fn refine(
    predictor: &mut Predictor,
    current: &Current,
    grids: &mut [Grid],
    dropped: &[Effect],
    round: usize,
) -> Result<(), String> {
    let settings = predictor.settings;
    let measured = predictor.measured;
    let live = |g: &&Grid| !dropped.contains(&g.effect);
    for pass in 1..=settings.widenings {
        let wanted: Vec<(Effect, f64)> = grids
            .iter()
            .filter(live)
            .filter(|g| g.end_still_falling(measured))
            .filter_map(|g| g.widen_point(measured).map(|u| (g.effect, u.exp())))
            .collect();
        if wanted.is_empty() {
            break;
        }
        let what = format!("widen {pass}");
        add_points(predictor, grids, &wanted, current, round, &what)?;
    }
    let mut ranked: Vec<(f64, usize)> = grids
        .iter()
        .enumerate()
        .filter(|(_, g)| live(g))
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
        let what = format!("refine {pass}");
        add_points(predictor, grids, &wanted, current, round, &what)?;
    }
    Ok(())
}

/// Full predictions (every seed) of an effect at `factor`, added to its grid; with a screen
/// on fewer seeds the screened points left are rescaled by the gain between the full and the
/// screened response ([`Grid::insert_full`]). Returns the factor and its predictions.
pub fn polish(
    predictor: &mut Predictor,
    current: &Current,
    grid: &mut Grid,
    factor: f64,
    round: usize,
) -> Result<(f64, Vec<Prediction>), String> {
    let what = if grid.full.is_empty() {
        format!("round {round}: re-run with {}", grid.effect.name())
    } else {
        format!(
            "round {round}: re-fit {} of {}",
            grid.full.len() + 1,
            grid.effect.name()
        )
    };
    // The grid holds u = ln factor: the run is made at exp(u), so point and run agree exactly.
    let u = factor.ln();
    let config = grid.effect.apply(current.config, u.exp());
    let full = predictor
        .predict(std::slice::from_ref(&config), &what)?
        .remove(0);
    if predictor.screens_every_seed(current.config) {
        grid.insert(u, full.clone());
    } else {
        let screened = predictor.screened_view(&config, current.config, current.predictions)?;
        grid.insert_full(u, full.clone(), screened, current.predictions);
    }
    Ok((u.exp(), full))
}

fn add_points(
    predictor: &mut Predictor,
    grids: &mut [Grid],
    points: &[(Effect, f64)],
    current: &Current,
    round: usize,
    what: &str,
) -> Result<(), String> {
    let configs: Vec<Config> = points
        .iter()
        .map(|&(e, f)| e.apply(current.config, f))
        .collect();
    let screened_all = predictor.screens_every_seed(current.config);
    let predictions = predictor.predict_screen(
        &configs,
        current.config,
        current.predictions,
        &format!("round {round}: {what}"),
    )?;
    for (&(effect, factor), p) in points.iter().zip(predictions) {
        let grid = grids
            .iter_mut()
            .find(|g| g.effect == effect)
            .expect("grid per effect");
        if screened_all {
            grid.insert(factor.ln(), p);
        } else {
            grid.insert_screened(factor.ln(), p);
        }
    }
    Ok(())
}

/// The screened effects by their best screened χ², as a progress line (what the screen ranks).
pub fn report_ranking(progress: &dyn Fn(&str), what: &str, m: &MeasuredSet, grids: &[Grid]) {
    let mut ranked: Vec<(f64, Effect)> = grids.iter().map(|g| (g.minimum(m).1, g.effect)).collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    let text: Vec<String> = ranked
        .iter()
        .map(|(chi2, e)| format!("{} {chi2:.2}", e.name()))
        .collect();
    progress(&format!("{what}: {}", text.join(", ")));
}

#[cfg(test)]
mod tests;
