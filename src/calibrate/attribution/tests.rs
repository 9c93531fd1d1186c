use super::*;
use crate::calibrate::detection::LIMIT_SCAN;
use crate::calibrate::gap::Prediction;

fn data() -> MeasuredSet {
    MeasuredSet::parse("[[sticking]]\nvelocity_m_s = 2.0\nsigma_m_s = 0.05\n", "t").unwrap()
}

fn sticking(v: f64) -> Vec<Prediction> {
    vec![Prediction::Sticking {
        velocity: v,
        resolution: 0.0,
    }]
}

/// A grid for an effect whose sticking speed goes as factor^power from 1 m/s.
fn power_grid(effect: Effect, power: f64, factors: &[f64]) -> Grid {
    let mut g = Grid::new(effect);
    for &f in factors {
        g.insert(f.ln(), sticking(f.powf(power)));
    }
    g
}

#[test]
fn the_fit_recovers_a_power_law_and_refines_where_needed() {
    let m = data();
    let g = power_grid(Effect::NormalDamping, 0.5, &[1.0 / 16.0, 1.0, 64.0]);
    let (u, _, _) = g.minimum(&m);
    // Linear interpolation in u of ln v is exact for a power law: factor 4.
    assert!((u.exp() / 4.0 - 1.0).abs() < 0.01, "{}", u.exp());
    assert!(g.next_point(&m, 0.05).is_some());
}

#[test]
fn decides_named_tied_or_nothing() {
    let m = data();
    let base = gap(&m, &sticking(1.0));
    let strong = power_grid(Effect::NormalDamping, 0.5, &[1.0 / 16.0, 1.0, 4.0, 64.0]);
    let none = power_grid(Effect::RollingStiffness, 0.0, &[1.0 / 8.0, 1.0, 16.0]);
    let (fits, d) = attribute(&m, &base, &[none.clone(), strong.clone()]);
    assert_eq!(d, Decision::Named(Effect::NormalDamping));
    // One observable (a sticking velocity): the best fit shares its confidence with the
    // three parameters outside the library that move it too, 1/(1 + 3).
    assert!(fits[0].explained > 0.99);
    assert!(
        (fits[0].confidence - 0.25).abs() < 1e-6,
        "{}",
        fits[0].confidence
    );
    let twin = power_grid(Effect::SurfaceEnergy, 1.0, &[0.5, 1.0, 2.0, 2.5]);
    let (_, d) = attribute(&m, &base, &[strong, twin]);
    assert_eq!(
        d,
        Decision::Undetermined {
            singles: vec![Effect::NormalDamping, Effect::SurfaceEnergy],
            pairs: Vec::new()
        }
        .then_sorted(&d)
    );
    let (_, d) = attribute(&m, &base, &[none]);
    assert_eq!(d, Decision::NoEffectExplains);
    let within = gap(&m, &sticking(2.01));
    let (_, d) = attribute(&m, &within, &[]);
    assert_eq!(d, Decision::WithinNoise);
}

/// Two curves (a compression curve at one pressure band and a sticking velocity) from
/// an effect that moves φ by `dphi` per unit ln factor and the sticking speed as
/// factor^power, measured with σ = 0.01 in φ and 0.05 m/s.
fn two_curves() -> MeasuredSet {
    MeasuredSet::parse(
        "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e5]\nphi = [0.3, 0.3]\n\
         phi_sigma = 0.01\n[[sticking]]\nvelocity_m_s = 2.0\nsigma_m_s = 0.05\n",
        "t",
    )
    .unwrap()
}

fn both(phi: f64, v: f64) -> Vec<Prediction> {
    vec![
        Prediction::Compression {
            phi: vec![phi; super::super::gap::TARGETS],
            scatter: vec![0.0; super::super::gap::TARGETS],
            seeds: 3,
        },
        Prediction::Sticking {
            velocity: v,
            resolution: 0.0,
        },
    ]
}

fn linear_grid(effect: Effect, dphi: f64, power: f64, factors: &[f64]) -> Grid {
    let mut g = Grid::new(effect);
    for &f in factors {
        g.insert(f.ln(), both(0.25 + dphi * f.ln(), f.powf(power)));
    }
    g
}

#[test]
fn detection_limits_follow_from_the_noise_by_hand() {
    // φ moves by 0.01 per unit ln f against σ = 0.01 (sticking unmoved): λ = (ln f)²,
    // and with two curves the limit is λ > χ²₉₅(2) − 2 = 3.99 (Wilson–Hilferty: 3.9994),
    // i.e. |ln f| > 2.0 = ln 7.39. With σ halved λ quadruples: |ln f| > 1.0.
    let m = two_curves();
    let g = linear_grid(
        Effect::RollingStiffness,
        0.01,
        0.0,
        &[1.0 / 64.0, 1.0, 64.0],
    );
    let d = detection_limit(&m, &g).unwrap();
    let threshold = chi2_quantile_95(2) - 2.0;
    let by_hand = threshold.sqrt().exp();
    let step = (64f64.ln() / LIMIT_SCAN as f64).exp();
    let (lo, hi) = (d.lower.unwrap(), d.upper.unwrap());
    assert!(hi >= by_hand && hi <= by_hand * step, "{hi} vs {by_hand}");
    assert!(lo <= 1.0 / by_hand && lo >= 1.0 / (by_hand * step), "{lo}");
    let half = d.upper_half_sigma.unwrap();
    let by_hand = (threshold / 4.0).sqrt().exp();
    assert!(
        half >= by_hand && half <= by_hand * step,
        "{half} vs {by_hand}"
    );
    // No simulated scatter: four times the samples change nothing.
    assert_eq!(d.upper_4x_samples, d.upper);
    assert!(d.hides(by_hand * 0.9) && !d.hides(hi * 1.01) && !d.hides(lo / 1.01));
    // A range that does not reach the limit gives none.
    let short = linear_grid(Effect::RollingStiffness, 0.01, 0.0, &[0.5, 1.0, 2.0]);
    assert_eq!(detection_limit(&m, &short).unwrap().upper, None);
    // The form switch has no factor that is the config's model.
    let mut form = linear_grid(Effect::DampingForm, 0.01, 0.0, &[0.5, 1.0, 2.0]);
    form.effect = Effect::DampingForm;
    assert!(detection_limit(&m, &form).is_none());
}

#[test]
fn a_fit_on_the_range_end_widens_to_the_limit_and_is_a_bound() {
    // Sticking 2 m/s needs factor 2^2.5 = 5.66 on a power 0.4 law: beyond the screened
    // x2 and beyond the first widening to x4; the second (x16) brackets it.
    let m = data();
    let mut g = power_grid(Effect::NormalDamping, 0.4, &[0.5, 1.0, 2.0]);
    let u = g.widen_point(&m).unwrap();
    assert!(
        (u - 2.0 * 2f64.ln()).abs() < 1e-12,
        "doubles the distance in ln f"
    );
    g.insert(u, sticking(u.exp().powf(0.4)));
    assert_eq!(g.minimum_at_end(&m), Some(true));
    let u = g.widen_point(&m).unwrap();
    assert!((u.exp() - 16.0).abs() < 1e-9);
    g.insert(u, sticking(u.exp().powf(0.4)));
    assert_eq!(g.minimum_at_end(&m), None);
    assert!((g.minimum(&m).0.exp() / 2f64.powf(2.5) - 1.0).abs() < 0.01);
    // An effect whose limit stops short of the answer: a bound at the limit.
    let mut e = power_grid(Effect::Density, -0.5, &[0.8, 1.0, 1.25]);
    while let Some(u) = e.widen_point(&m) {
        e.insert(u, sticking(u.exp().powf(-0.5)));
    }
    let base = gap(&m, &sticking(1.0));
    let (fits, _) = attribute(&m, &base, &[e]);
    let b = fits[0].bound.as_ref().expect("a bound");
    assert!(!b.upper && b.limit.is_some());
    let (limit, _, _) = Effect::Density.limits();
    assert!((fits[0].factor - limit).abs() < 1e-9, "{}", fits[0].factor);
    assert!(fits[0].factor_text().starts_with("<="));
}

#[test]
fn an_effect_that_fits_one_curve_but_not_the_other_does_not_predict_it() {
    // Data: φ 0.30 and sticking 2 m/s. The effect moves φ from 0.25 by 0.1 per unit ln f
    // (needs f = e^0.5) and sticking as f^0.5 from 1 m/s (needs f = 4): fitted to either
    // curve alone it misses the other by far more than the noise (sticking 1.28 m/s
    // against 2 ± 0.05; φ 0.389 against 0.30 ± 0.01).
    let m = two_curves();
    let g = linear_grid(Effect::SurfaceEnergy, 0.1, 0.5, &[1.0 / 16.0, 1.0, 16.0]);
    let base = gap(&m, &both(0.25, 1.0));
    let (fits, d) = attribute(&m, &base, &[g]);
    assert_eq!(fits[0].held_out.len(), 2);
    assert!(fits[0].held_out.iter().all(|h| !h.predicted));
    match d {
        Decision::Unpredictive { effect, fails } => {
            assert_eq!(effect, Effect::SurfaceEnergy);
            assert_eq!(fails.len(), 2);
        }
        other => panic!("{other:?}"),
    }
    // One that moves both consistently (φ: 0.05 per ln f reaches 0.30 at f = e; sticking
    // as f^(ln 2) reaches 2 m/s at f = e too) predicts each from the other.
    let good = linear_grid(
        Effect::RollingStiffness,
        0.05,
        2f64.ln(),
        &[1.0 / 16.0, 1.0, 16.0],
    );
    let (fits, d) = attribute(&m, &base, &[good]);
    assert!(
        fits[0].held_out.iter().all(|h| h.predicted),
        "{:?}",
        fits[0].held_out
    );
    assert_eq!(d, Decision::Named(Effect::RollingStiffness));
}

#[test]
fn the_two_damping_forms_never_tie_and_the_config_form_wins_a_near_tie() {
    let m = data();
    let base = gap(&m, &sticking(1.0));
    let own = power_grid(Effect::NormalDamping, 0.5, &[1.0 / 16.0, 1.0, 4.0, 64.0]);
    let mut other = power_grid(Effect::DampingForm, 0.5, &[1.0 / 16.0, 1.0, 4.0, 64.0]);
    other.effect = Effect::DampingForm;
    let (_, d) = attribute(&m, &base, &[other.clone(), own]);
    assert_eq!(d, Decision::Named(Effect::NormalDamping));
    // The other form alone, clearly better: chosen.
    let worse = power_grid(Effect::NormalDamping, 0.1, &[1.0 / 16.0, 1.0, 16.0]);
    let (_, d) = attribute(&m, &base, &[worse, other]);
    assert_eq!(d, Decision::Named(Effect::DampingForm));
}

impl Decision {
    /// The same set of effects in the order `other` lists them (ties are ordered by χ²).
    fn then_sorted(self, other: &Decision) -> Decision {
        match (self, other) {
            (
                Decision::Undetermined {
                    singles: mut a,
                    pairs,
                },
                Decision::Undetermined { singles: b, .. },
            ) => {
                a.sort_by_key(|e| b.iter().position(|x| x == e));
                Decision::Undetermined { singles: a, pairs }
            }
            (s, _) => s,
        }
    }
}
