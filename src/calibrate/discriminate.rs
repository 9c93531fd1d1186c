//! What would tell an undetermined result apart: the two leading explanations simulated on
//! measurements the data do not hold (the uni and omni curves to higher pressure, a sticking
//! velocity), each scored by the χ² that data made by one explanation would show against the
//! other at the data's noise ([`super::gap::shift_chi2`], one degree per curve as in the gap).
//! A second wall speed would often separate more, but the calibration simulates every curve at
//! the config's wall speed, so it could not use such data: it is not proposed.

use super::attribution::{Decision, EffectFit};
use super::gap::shift_chi2;
use super::measured::{log_spaced, CompressionCurve, Geometry, MeasuredSet, StickingVelocity};
use super::pairs::{find_pair, PairFit};
use super::predictor::Predictor;
use super::simulate::RunCache;
use super::workflow::Settings;
use crate::config::Config;

/// Relative 1σ of a proposed sticking velocity: the synthetic data's default (5%).
const STICKING_SIGMA: f64 = 0.05;
/// Upper pressure of a proposed curve to higher pressure [Pa].
const HIGH_PRESSURE: f64 = 1e6;
/// Points per proposed curve.
const POINTS: usize = 10;

/// One proposed measurement and how far apart it puts the two explanations.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub what: String,
    /// χ² of data made by the first explanation against the second (noise aside).
    pub separation: f64,
}

/// The proposals for one undetermined round, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct Discrimination {
    /// The two leading explanations, as "effect x1.23" or "a x1 + b x2".
    pub between: [String; 2],
    pub proposals: Vec<Proposal>,
    /// Compressions and sticking runs the proposals requested (cache hits included).
    pub runs: usize,
}

/// The data's mean φ uncertainty (0.005, the synthetic default, without compression data).
fn data_sigma(m: &MeasuredSet) -> f64 {
    let all: Vec<f64> = m
        .compression
        .iter()
        .flat_map(|c| c.phi_sigma.iter().copied())
        .collect();
    match all.len() {
        0 => 0.005,
        n => all.iter().sum::<f64>() / n as f64,
    }
}

fn curve(geometry: Geometry, (lo, hi): (f64, f64), sigma: f64) -> CompressionCurve {
    CompressionCurve {
        name: format!("{geometry:?}").to_lowercase(),
        geometry,
        pressure: log_spaced(lo, hi, POINTS),
        // The values do not enter the separation: only the pressures and σ do.
        phi: vec![0.3; POINTS],
        phi_sigma: vec![sigma; POINTS],
        wall_speed: None,
    }
}

/// The measurements proposed for data `m`: (description, data set).
fn candidates(m: &MeasuredSet) -> Vec<(String, MeasuredSet)> {
    let sigma = data_sigma(m);
    let p_lo = m
        .compression
        .iter()
        .map(|c| c.pressure_range().0)
        .fold(f64::INFINITY, f64::min)
        .min(1e2);
    let set = |compression: Vec<CompressionCurve>, sticking: Vec<StickingVelocity>| MeasuredSet {
        source: m.source.clone(),
        compression,
        sticking,
    };
    let mut out = Vec::new();
    for g in [Geometry::Uni, Geometry::Omni] {
        out.push((
            format!(
                "the {} curve to {HIGH_PRESSURE:.0e} Pa (σ_φ {sigma:.4})",
                format!("{g:?}").to_lowercase()
            ),
            set(vec![curve(g, (p_lo, HIGH_PRESSURE), sigma)], Vec::new()),
        ));
    }
    if m.sticking.is_empty() {
        out.push((
            format!("the sticking velocity (σ {:.0}%)", 100.0 * STICKING_SIGMA),
            set(
                Vec::new(),
                vec![StickingVelocity {
                    name: "sticking".into(),
                    velocity: 1.0,
                    sigma: f64::NAN,
                }],
            ),
        ));
    }
    out
}

/// The two leading explanations of an undetermined decision, applied to `now`: the single
/// effects first (at their 1-D fits), then the pairs (at their joint fits).
pub fn leading_explanations(
    decision: &Decision,
    fits: &[EffectFit],
    pairs: &[PairFit],
    now: &Config,
) -> Option<[(String, Config); 2]> {
    let Decision::Undetermined {
        singles,
        pairs: tied,
    } = decision
    else {
        return None;
    };
    let singles = singles.iter().filter_map(|e| {
        let f = fits.iter().find(|f| f.effect == *e)?;
        Some((
            format!("{} x{:.3}", e.name(), f.factor),
            e.apply(now, f.factor),
        ))
    });
    let pairs = tied.iter().filter_map(|t| {
        let p = find_pair(pairs, *t)?;
        let label = format!(
            "{} x{:.3} + {} x{:.3}",
            t[0].name(),
            p.factors[0],
            t[1].name(),
            p.factors[1]
        );
        let config = t[1].apply(&t[0].apply(now, p.factors[0]), p.factors[1]);
        Some((label, config))
    });
    let mut all = singles.chain(pairs);
    Some([all.next()?, all.next()?])
}

/// Scores every proposed measurement for the two explanations (labels and configs).
pub fn discriminate(
    m: &MeasuredSet,
    explanations: [(String, Config); 2],
    settings: &Settings,
    cache: &RunCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Discrimination, String> {
    let mut proposals = Vec::new();
    let mut runs = 0;
    for (what, mut set) in candidates(m) {
        let configs = explanations.clone().map(|(_, c)| c);
        let mut predictor = Predictor::new(&set, cache, settings, progress);
        let mut p = predictor.predict(&configs, &format!("discriminate: {what}"))?;
        runs += predictor.cost.runs();
        let (b, a) = (p.pop().expect("two"), p.pop().expect("two"));
        // A proposed sticking velocity's σ: relative to the first explanation's value.
        if let (Some(s), Some(super::gap::Prediction::Sticking { velocity, .. })) =
            (set.sticking.first_mut(), a.last())
        {
            s.velocity = *velocity;
            s.sigma = STICKING_SIGMA * velocity;
        }
        let separation = shift_chi2(&set, &a, &b, (1.0, 1.0)).iter().sum();
        proposals.push(Proposal { what, separation });
    }
    proposals.sort_by(|x, y| y.separation.total_cmp(&x.separation));
    Ok(Discrimination {
        between: explanations.map(|(label, _)| label),
        proposals,
        runs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::effects::Effect;

    fn omni(sigma: &str) -> String {
        format!(
            "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e4]\nphi = [0.2, 0.3]\n\
             phi_sigma = {sigma}\n"
        )
    }

    #[test]
    fn proposals_cover_higher_pressure_and_a_missing_sticking_velocity() {
        let m = MeasuredSet::parse(&omni("[0.004, 0.008]"), "t").unwrap();
        // σ: the mean of the data's, (0.004 + 0.008) / 2.
        assert!((data_sigma(&m) - 0.006).abs() < 1e-12);
        let c = candidates(&m);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0].1.compression[0].geometry, Geometry::Uni);
        assert_eq!(c[0].1.compression[0].pressure_range(), (1e2, HIGH_PRESSURE));
        assert_eq!(c[1].1.compression[0].geometry, Geometry::Omni);
        assert_eq!(c[2].1.sticking.len(), 1);
        // With a sticking velocity measured, none is proposed.
        let with = omni("0.005") + "[[sticking]]\nvelocity_m_s = 1.0\nsigma_m_s = 0.05\n";
        let m = MeasuredSet::parse(&with, "t").unwrap();
        assert_eq!(candidates(&m).len(), 2);
    }

    #[test]
    fn the_two_leading_explanations_are_the_singles_first_then_the_pairs() {
        let base = Config::default();
        let d = Decision::Undetermined {
            singles: vec![Effect::Density],
            pairs: vec![[Effect::RollingStiffness, Effect::SurfaceEnergy]],
        };
        let pair = PairFit {
            effects: [Effect::RollingStiffness, Effect::SurfaceEnergy],
            factors: [4.0, 0.5],
            intervals: [(3.0, 5.0), (0.4, 0.6)],
            chi2: 1.0,
            alone: [10.0, 10.0],
            on_bound: [false, false],
            pinned: None,
            simulated_chi2: Some(1.5),
        };
        // Without a fit for the single, only the pair is known: no two explanations.
        assert!(leading_explanations(&d, &[], std::slice::from_ref(&pair), &base).is_none());
        assert!(leading_explanations(&Decision::WithinNoise, &[], &[], &base).is_none());
        let fit = EffectFit {
            effect: Effect::Density,
            factor: 1.2,
            interval: (1.1, 1.25),
            chi2: 2.0,
            explained: 0.9,
            chi2_at_range_ends: (9.0, 9.0),
            confidence: 0.5,
            grid_factors: vec![0.8, 1.0, 1.25],
            bound: None,
            held_out: Vec::new(),
        };
        let [a, b] = leading_explanations(&d, &[fit], &[pair], &base).unwrap();
        assert_eq!(a.0, "density x1.200");
        assert_eq!(b.0, "rolling_stiffness x4.000 + surface_energy x0.500");
        assert_eq!(a.1, Effect::Density.apply(&base, 1.2));
        let both = Effect::SurfaceEnergy.apply(&Effect::RollingStiffness.apply(&base, 4.0), 0.5);
        assert_eq!(b.1, both);
    }
}
