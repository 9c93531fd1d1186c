//! When the answer may lie outside the effect library: the best effects tie, the best fit sits
//! on a bound of its searched range, or the best fit leaves a gap beyond noise (a shape no
//! effect matches), or the signal rests on one observable. Then the report names what the
//! model itself suggests instead: the constants the effects' formulas share with others (a
//! factor on one of them can stand for a change of the other), and the setup of the
//! simulation.

use super::attribution::{Decision, EffectFit, Grid};
use super::effects::Effect;
use super::gap::{chi2_quantile_95, shift_chi2, Gap};
use super::measured::MeasuredSet;

/// Why a parameter outside the library may be the cause, and which ones.
#[derive(Clone, Debug, PartialEq)]
pub struct OutsideLibrary {
    /// The signs seen: ties, bounds, a gap left beyond noise.
    pub signs: Vec<String>,
    /// Candidates outside the library, each counted as one equally good explanation in the
    /// confidences.
    pub candidates: Vec<String>,
}

/// What the formula of an effect shares with constants the library does not vary (from the
/// contact model's closed forms, docs/physics.md).
pub fn shared_constants(effect: Effect) -> &'static [&'static str] {
    match effect {
        Effect::RollingStiffness => &[
            "the pull-off force F_c = 3πγR the rolling stiffness k_r = 4F_c/R is built on \
             (surface energy, radius)",
        ],
        Effect::SlidingStiffness | Effect::TwistingStiffness => &[
            "the shear modulus G* = E/(4(2−ν)(1+ν)) and contact radius a₀ the sliding and twisting \
             stiffnesses are built on (Young's modulus, Poisson's ratio)",
        ],
        Effect::NormalDamping | Effect::DampingForm => &[
            "Young's modulus and Poisson's ratio: the viscoelastic coefficient 2E*T_vis a/ν² \
             makes T_vis interchangeable with E and ν",
        ],
        Effect::SurfaceEnergy => &[
            "the radius and E*: F_c = 3πγR and a₀ ∝ (γR²/E*)^(1/3) trade γ against them",
        ],
        Effect::CriticalRollingLength => &[
            "the rolling energy F_c ξ_crit: ξ_crit trades against the surface energy and radius",
        ],
        Effect::YoungsModulus => &["Poisson's ratio: E* = E/(2(1−ν²))"],
        Effect::MonomerRadius => &["the monomer size distribution, which one radius stands for"],
        Effect::Density => &["the time scale: mass enters the dynamics only against the wall speed"],
        Effect::SideWallStrength => &[
            "the three wall factors (rolling, sliding, twisting) apart: the library scales them together",
        ],
    }
}

/// What the simulation's setup could get wrong, by kind of data.
fn setup_candidates(has_compression: bool) -> Vec<String> {
    let mut v = Vec::new();
    if has_compression {
        v.extend(
            [
                "the wall speed",
                "how the sample was prepared (its packing before compression)",
                "the sample size (boundary effects)",
            ]
            .map(str::to_string),
        );
    }
    v
}

/// The signs that the library may not hold the cause, and the candidates; None when the best
/// fit is clear, inside its range and leaves the data within noise, or when there is nothing
/// to explain.
pub fn outside_library(
    baseline: &Gap,
    fits: &[EffectFit],
    decision: &Decision,
    has_compression: bool,
) -> Option<OutsideLibrary> {
    if matches!(decision, Decision::WithinNoise) {
        return None;
    }
    let best = fits.first()?;
    let involved: Vec<Effect> = match decision {
        Decision::Undetermined { singles, pairs } => singles
            .iter()
            .chain(pairs.iter().flatten())
            .copied()
            .collect(),
        Decision::NamedPair(p) => p.to_vec(),
        _ => vec![best.effect],
    };
    let mut signs = Vec::new();
    if let Decision::Undetermined { singles, pairs } = decision {
        let names: Vec<String> = singles
            .iter()
            .map(|e| e.name().to_string())
            .chain(
                pairs
                    .iter()
                    .map(|p| format!("{} + {}", p[0].name(), p[1].name())),
            )
            .collect();
        let what = match pairs.is_empty() {
            true => "effects",
            false => "explanations",
        };
        signs.push(format!("the best {what} tie ({})", names.join(", ")));
    }
    let on_bound: Vec<&str> = fits
        .iter()
        .filter(|f| involved.contains(&f.effect) && f.bound.is_some())
        .map(|f| f.effect.name())
        .collect();
    if !on_bound.is_empty() {
        signs.push(format!(
            "the fit of {} sits on a bound of its searched range",
            on_bound.join(", ")
        ));
    }
    if best.chi2 > baseline.threshold {
        signs.push(format!(
            "the best fit ({}) leaves χ² = {:.2} above the noise threshold {:.2}: a gap whose \
             shape no effect matches",
            best.effect.name(),
            best.chi2,
            baseline.threshold
        ));
    }
    if signs.is_empty() {
        return None;
    }
    let mut candidates: Vec<String> = Vec::new();
    for e in &involved {
        for c in shared_constants(*e) {
            if !candidates.iter().any(|k| k == c) {
                candidates.push(c.to_string());
            }
        }
    }
    candidates.extend(setup_candidates(has_compression));
    Some(OutsideLibrary { signs, candidates })
}

/// The signal rests on one observable: only this curve is beyond noise at the baseline, so
/// whatever moves it explains the data as well as the named effect.
#[derive(Clone, Debug, PartialEq)]
pub struct SingleObservable {
    pub curve: String,
    /// Library effects whose searched range moves that curve beyond its noise.
    pub library: Vec<Effect>,
    /// What moves it outside the library.
    pub outside: Vec<&'static str>,
}

/// What moves a sticking velocity or a compression curve that the library does not hold.
fn outside_movers(sticking: bool) -> Vec<&'static str> {
    if sticking {
        vec![
            "Poisson's ratio",
            "off-centre impacts and spinning grains in the experiment",
            "grain shape and surface roughness",
        ]
    } else {
        vec![
            "the wall speed",
            "how the sample was prepared (its packing before compression)",
            "the monomer size distribution",
            "the sample size (boundary effects)",
        ]
    }
}

/// Whether the baseline signal rests on one curve, and what moves that curve.
pub fn single_observable(
    m: &MeasuredSet,
    baseline: &Gap,
    grids: &[Grid],
) -> Option<SingleObservable> {
    let limit = chi2_quantile_95(1);
    let beyond: Vec<usize> = (0..baseline.curves.len())
        .filter(|&j| baseline.curves[j].chi2 > limit)
        .collect();
    let [j] = beyond[..] else { return None };
    let mut library: Vec<Effect> = Vec::new();
    for g in grids {
        let Some((_, reference)) = g.points.iter().find(|(u, _)| *u == 0.0) else {
            continue;
        };
        if !g.effect.identity_at_one() {
            continue;
        }
        let moves = [&g.points[0].1, &g.points[g.points.len() - 1].1]
            .iter()
            .any(|end| shift_chi2(m, reference, end, (1.0, 1.0))[j] > limit);
        if moves && !library.contains(&g.effect.family()) {
            library.push(g.effect.family());
        }
    }
    Some(SingleObservable {
        curve: baseline.curves[j].name.clone(),
        library,
        outside: outside_movers(j >= m.compression.len()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::attribution::Bound;

    fn fit(effect: Effect, chi2: f64, bound: bool) -> EffectFit {
        EffectFit {
            effect,
            factor: 2.0,
            interval: (1.5, 2.5),
            chi2,
            explained: 0.5,
            chi2_at_range_ends: (9.0, 9.0),
            confidence: 0.0,
            grid_factors: vec![0.25, 1.0, 4.0],
            bound: bound.then_some(Bound {
                upper: true,
                limit: None,
            }),
            held_out: Vec::new(),
        }
    }

    fn baseline(threshold: f64) -> Gap {
        Gap {
            curves: Vec::new(),
            chi2: 40.0,
            threshold,
        }
    }

    #[test]
    fn a_clear_fit_inside_its_range_that_closes_the_gap_needs_nothing_outside() {
        let fits = [
            fit(Effect::SurfaceEnergy, 1.0, false),
            fit(Effect::Density, 9.0, false),
        ];
        let named = Decision::Named(Effect::SurfaceEnergy);
        assert_eq!(outside_library(&baseline(3.0), &fits, &named, true), None);
        assert_eq!(
            outside_library(&baseline(3.0), &fits, &Decision::WithinNoise, true),
            None
        );
    }

    #[test]
    fn ties_bounds_and_a_gap_left_each_raise_it_with_the_formulas_constants() {
        let tied = Decision::Undetermined {
            singles: vec![Effect::NormalDamping, Effect::SurfaceEnergy],
            pairs: Vec::new(),
        };
        let fits = [
            fit(Effect::NormalDamping, 1.0, false),
            fit(Effect::SurfaceEnergy, 1.5, false),
        ];
        let o = outside_library(&baseline(3.0), &fits, &tied, false).unwrap();
        assert_eq!(o.signs.len(), 1, "{o:?}");
        assert!(o.candidates[0].contains("2E*T_vis a/ν²"), "{o:?}");
        assert!(o.candidates[1].contains("F_c = 3πγR"), "{o:?}");
        assert_eq!(o.candidates.len(), 2, "sticking data: no compression setup");

        let bounded = [fit(Effect::YoungsModulus, 1.0, true)];
        let named = Decision::Named(Effect::YoungsModulus);
        let o = outside_library(&baseline(3.0), &bounded, &named, true).unwrap();
        assert!(
            o.signs[0].contains("youngs_modulus sits on a bound"),
            "{o:?}"
        );
        assert!(o.candidates[0].contains("Poisson"), "{o:?}");
        assert!(o.candidates.iter().any(|c| c == "the wall speed"), "{o:?}");

        let left = [fit(Effect::Density, 7.0, false)];
        let o = outside_library(
            &baseline(3.0),
            &left,
            &Decision::Named(Effect::Density),
            true,
        )
        .unwrap();
        assert!(
            o.signs[0].contains("χ² = 7.00 above the noise threshold 3.00"),
            "{o:?}"
        );
    }
}
