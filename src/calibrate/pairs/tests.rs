use super::*;
use crate::calibrate::attribution::attribute;
use crate::calibrate::gap::TARGETS;

/// Omni and uni curves, each measured at φ = 0.30 at two pressures with σ = 0.01.
fn omni_and_uni() -> MeasuredSet {
    let curve = |g: &str| {
        format!(
            "[[compression]]\ngeometry = \"{g}\"\npressure_pa = [1e2, 1e5]\nphi = [0.3, 0.3]\n\
             phi_sigma = 0.01\n"
        )
    };
    MeasuredSet::parse(&(curve("omni") + &curve("uni")), "t").unwrap()
}

fn curves(omni: f64, uni: f64) -> Vec<Prediction> {
    [omni, uni]
        .map(|phi| Prediction::Compression {
            phi: vec![phi; TARGETS],
            scatter: vec![0.0; TARGETS],
            seeds: 3,
        })
        .to_vec()
}

/// An effect moving omni by `omni` and uni by `uni` per unit ln factor from (0.25, 0.25),
/// simulated at 1/8, 1 and 8.
fn linear(effect: Effect, omni: f64, uni: f64) -> Grid {
    let mut g = Grid::new(effect);
    for f in [0.125f64, 1.0, 8.0] {
        let u = f.ln();
        g.insert(u, curves(0.25 + omni * u, 0.25 + uni * u));
    }
    g
}

fn phi(p: &Prediction) -> f64 {
    match p {
        Prediction::Compression { phi, .. } => phi[0],
        Prediction::Sticking { velocity, .. } => *velocity,
    }
}

#[test]
fn responses_add_in_phi_and_multiply_in_sticking_speed() {
    let c = &curves(0.25, 0.25)[0];
    let (a, b) = (&curves(0.27, 0.0)[0], &curves(0.22, 0.0)[0]);
    assert!((phi(&combine(c, a, b)) - 0.24).abs() < 1e-12);
    let v = |x: f64| Prediction::Sticking {
        velocity: x,
        resolution: 0.0,
    };
    // 1 m/s moved ×2 by one effect and ×1.5 by the other: 3 m/s.
    assert!((phi(&combine(&v(1.0), &v(2.0), &v(1.5))) - 3.0).abs() < 1e-12);
}

/// Data that need effect A (omni only, f = e) and effect B (uni only, f = e): no single effect
/// fits, the pair does. Each curve counts as one degree (its χ² is the mean of (Δ/σ)² over its
/// points): a factor off by Δu moves its curve by 0.05 Δu = 5σ Δu, χ² = 25 Δu², so the
/// interval is Δu = ±0.2 by hand, and either effect alone leaves the other curve at χ² = 25.
#[test]
fn two_effects_on_two_curves_are_found_together_and_named_as_a_pair() {
    let m = omni_and_uni();
    let base = gap(&m, &curves(0.25, 0.25));
    let a = linear(Effect::RollingStiffness, 0.05, 0.0);
    let b = linear(Effect::SurfaceEnergy, 0.0, 0.05);
    let grids = [a, b];
    let (fits, single) = attribute(&m, &base, &grids);
    let pairs = fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &[]);
    assert_eq!(pairs.len(), 1);
    let p = &pairs[0];
    assert!(p.alone.iter().all(|&c| (c - 25.0).abs() < 0.01), "{p:?}");
    assert!(p.chi2 < 0.05, "{p:?}");
    assert!(p.needs_both());
    let e = std::f64::consts::E;
    for k in 0..2 {
        assert!((p.factors[k] / e - 1.0).abs() < 0.02, "{:?}", p.factors);
        // Δχ² = 1 at |Δu| = 0.2; the coarse profile may add one step (ln 64 / 32 = 0.13).
        let (lo, hi) = p.intervals[k];
        let by_hand = (e * (-0.2f64).exp(), e * 0.2f64.exp());
        assert!(lo <= by_hand.0 && lo >= by_hand.0 * (-0.14f64).exp(), "{lo}");
        assert!(hi >= by_hand.1 && hi <= by_hand.1 * 0.14f64.exp(), "{hi}");
    }
    assert_eq!(
        reconsider(single, &fits, &pairs),
        Decision::NamedPair([Effect::RollingStiffness, Effect::SurfaceEnergy])
    );
}

/// A third effect that moves both curves alike fits the same data alone: the single effect is
/// no longer named, the result is undetermined with the pair beside it.
#[test]
fn a_single_effect_that_stands_in_for_a_pair_is_not_named_alone() {
    let m = omni_and_uni();
    let base = gap(&m, &curves(0.25, 0.25));
    let grids = [
        linear(Effect::RollingStiffness, 0.05, 0.0),
        linear(Effect::SurfaceEnergy, 0.0, 0.05),
        linear(Effect::NormalDamping, 0.05, 0.05),
    ];
    let (fits, single) = attribute(&m, &base, &grids);
    assert_eq!(single, Decision::Named(Effect::NormalDamping));
    let pairs = fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &[]);
    assert_eq!(pairs.len(), 3, "no detection limits given: free fits only");
    assert_eq!(
        reconsider(single, &fits, &pairs),
        Decision::Undetermined {
            singles: vec![Effect::NormalDamping],
            pairs: vec![[Effect::RollingStiffness, Effect::SurfaceEnergy]],
        }
    );
}

/// One effect hidden alone (omni moved, uni as measured): the others move uni only, so every
/// pair either reduces to it (the partner not needed) or cannot move omni; the single effect
/// stays named.
#[test]
fn a_single_hidden_effect_stays_named_when_pairs_only_add_a_spare_effect() {
    let m = MeasuredSet::parse(
        "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e5]\nphi = [0.3, 0.3]\n\
         phi_sigma = 0.01\n[[compression]]\ngeometry = \"uni\"\npressure_pa = [1e2, 1e5]\n\
         phi = [0.25, 0.25]\nphi_sigma = 0.01\n",
        "t",
    )
    .unwrap();
    let base = gap(&m, &curves(0.25, 0.25));
    let grids = [
        linear(Effect::RollingStiffness, 0.05, 0.0),
        linear(Effect::SurfaceEnergy, 0.0, 0.05),
        linear(Effect::Density, 0.0, 0.03),
    ];
    let (fits, single) = attribute(&m, &base, &grids);
    assert_eq!(single, Decision::Named(Effect::RollingStiffness));
    let pairs = fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &[]);
    assert!(pairs.iter().all(|p| !p.needs_both()), "{pairs:?}");
    assert_eq!(
        reconsider(single.clone(), &fits, &pairs),
        Decision::Named(Effect::RollingStiffness)
    );
    // The same pair made to need both (its simulated χ² far below either alone) and to fit
    // as well as the single effect: it is a rival, and the result undetermined.
    let mut rigged = pairs.clone();
    let k = rigged
        .iter()
        .position(|p| !p.contains(Effect::RollingStiffness))
        .unwrap();
    rigged[k].simulated_chi2 = Some(fits[0].chi2);
    rigged[k].alone = [fits[0].chi2 + 10.0; 2];
    assert!(reconsider(single, &fits, &rigged).is_undetermined());
}

/// The two damping forms are one family: never paired with each other.
#[test]
fn effects_of_one_family_are_not_paired() {
    let m = omni_and_uni();
    let mut form = linear(Effect::DampingForm, 0.05, 0.0);
    form.effect = Effect::DampingForm;
    let grids = [form, linear(Effect::NormalDamping, 0.0, 0.05)];
    let base = gap(&m, &curves(0.25, 0.25));
    let (fits, _) = attribute(&m, &base, &grids);
    assert!(fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &[]).is_empty());
}

/// The single effect S fits exactly; C moves omni like S and uni half as much. With C held at
/// its detection limit (λ = (25 + 6.25) u² > χ²₉₅(2) − 2 = 3.99: u = 0.357 by hand), S at
/// u = 0.732 leaves ±0.0045 on each curve, χ² ≈ 0.40 by hand: S with C present at a level
/// the data would show alone fits within Δχ² = 2 of S alone, and C alone (χ² 5 at u = 1.2)
/// does not, so S is not singled out. A, which moves omni only, cannot be compensated by S
/// (S must keep uni): held at its limit it leaves χ² 4, and is no alternative with S; but C
/// at u = 2 with A at u = −1 fits exactly (uni 0.05, omni 0.10 − 0.05), a free pair that
/// needs both.
#[test]
fn a_second_effect_at_a_detectable_level_that_the_first_compensates_leaves_it_undetermined() {
    use crate::calibrate::detection::detection_limit;
    let m = omni_and_uni();
    let base = gap(&m, &curves(0.25, 0.25));
    let s = linear(Effect::NormalDamping, 0.05, 0.05);
    let c = linear(Effect::RollingStiffness, 0.05, 0.025);
    let a = linear(Effect::SurfaceEnergy, 0.05, 0.0);
    let grids = [s, c, a];
    let (fits, single) = attribute(&m, &base, &grids);
    assert_eq!(single, Decision::Named(Effect::NormalDamping));
    let detection: Vec<_> = grids
        .iter()
        .filter_map(|g| detection_limit(&m, g))
        .collect();
    let limit_c = detection[1].upper.unwrap().ln();
    assert!((limit_c - 0.357).abs() < 0.01, "{limit_c}");
    let pairs = fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &detection);
    let pinned_c = pairs
        .iter()
        .find(|p| p.effects == [Effect::NormalDamping, Effect::RollingStiffness] && p.pinned == Some(1))
        .unwrap();
    // Held either way (the responses are linear, the limits symmetric) on the scan's coarse
    // points beyond the limit (steps of ln 64 / 32 = 0.13 in u): χ² grows as u², from 0.40 at
    // the limit to at most 0.40 (0.487 / 0.357)² = 0.75 a step beyond.
    let u_c = pinned_c.factors[1].ln().abs();
    assert!(u_c >= limit_c - 1e-9 && u_c <= limit_c + 0.13, "{pinned_c:?}");
    let by_hand = 0.40 * (u_c / 0.357).powi(2);
    assert!((pinned_c.chi2 / by_hand - 1.0).abs() < 0.05, "{pinned_c:?} vs {by_hand}");
    assert!(pinned_c.needs_both());
    let pinned_a = pairs
        .iter()
        .find(|p| p.effects == [Effect::NormalDamping, Effect::SurfaceEnergy] && p.pinned == Some(1))
        .unwrap();
    assert!(pinned_a.chi2 > 3.0, "{pinned_a:?}");
    assert_eq!(
        reconsider(single, &fits, &pairs),
        Decision::Undetermined {
            singles: vec![Effect::NormalDamping],
            pairs: vec![
                [Effect::RollingStiffness, Effect::SurfaceEnergy],
                [Effect::NormalDamping, Effect::RollingStiffness]
            ],
        }
    );
}
