use super::*;
use crate::calibrate::attribution::attribute;
use crate::calibrate::gap::TARGETS;

/// Omni and uni curves measured at φ `omni` and `uni` at two pressures with σ = 0.01, and a
/// sticking velocity of 1 ± 0.05 m/s that no effect here moves: three curves, the fewest
/// that pairs are fitted on ([`PAIR_MIN_CURVES`]).
fn data(omni: f64, uni: f64) -> MeasuredSet {
    let curve = |g: &str, phi: f64| {
        format!(
            "[[compression]]\ngeometry = \"{g}\"\npressure_pa = [1e2, 1e5]\nphi = [{phi}, {phi}]\n\
             phi_sigma = 0.01\n"
        )
    };
    let sticking = "[[sticking]]\nvelocity_m_s = 1.0\nsigma_m_s = 0.05\n";
    MeasuredSet::parse(&(curve("omni", omni) + &curve("uni", uni) + sticking), "t").unwrap()
}

fn omni_and_uni() -> MeasuredSet {
    data(0.3, 0.3)
}

fn curves(omni: f64, uni: f64) -> Vec<Prediction> {
    let mut p: Vec<Prediction> = [omni, uni]
        .map(|phi| Prediction::Compression {
            phi: vec![phi; TARGETS],
            scatter: vec![0.0; TARGETS],
            seeds: 3,
        })
        .to_vec();
    p.push(Prediction::Sticking {
        velocity: 1.0,
        resolution: 0.0,
    });
    p
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
        assert!(
            lo <= by_hand.0 && lo >= by_hand.0 * (-0.14f64).exp(),
            "{lo}"
        );
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
    let m = data(0.3, 0.25);
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

/// Data at omni 0.30, uni 0.29. S moves both curves by 0.05 per unit ln factor: alone it
/// leaves ±0.005 on each, χ² = 0.5 by hand. C moves omni by 0.05 and uni by 0.0125: alone
/// χ² = 7.1. With C held at u_c, S's best leaves χ² = (3.75 u_c − 1)² / 2 by hand; at C's
/// detection limit (λ = 26.56 u² > χ²₉₅(3) − 3 = 4.775: u_c = 0.424) that is 0.17. It fits
/// better than S alone, but by less than Δχ² = 2: no evidence for C, and no rival. A moves
/// omni only: held at its limit with S, χ² 0.70. C with A fits within Δχ² = 2 of S (C at the
/// end of its range, χ² 1.96), a free pair that needs both: the result is undetermined.
#[test]
fn pinned_fits_follow_the_hand_computed_chi2_and_free_pairs_tie() {
    use crate::calibrate::detection::detection_limit;
    let m = data(0.3, 0.29);
    let base = gap(&m, &curves(0.25, 0.25));
    let s = linear(Effect::NormalDamping, 0.05, 0.05);
    let c = linear(Effect::RollingStiffness, 0.05, 0.0125);
    let a = linear(Effect::SurfaceEnergy, 0.05, 0.0);
    let grids = [s, c, a];
    let (fits, single) = attribute(&m, &base, &grids);
    assert_eq!(single, Decision::Named(Effect::NormalDamping));
    assert!((fits[0].chi2 - 0.5).abs() < 0.01, "{}", fits[0].chi2);
    let detection: Vec<_> = grids
        .iter()
        .filter_map(|g| detection_limit(&m, g))
        .collect();
    let limit_c = detection[1].upper.unwrap().ln();
    assert!((limit_c - 0.424).abs() < 0.01, "{limit_c}");
    let pairs = fit_pairs(&m, &grids, &curves(0.25, 0.25), &fits, &detection);
    let pinned = |e: [Effect; 2]| {
        pairs
            .iter()
            .find(|p| p.effects == e && p.pinned == Some(1))
            .unwrap()
    };
    let pinned_c = pinned([Effect::NormalDamping, Effect::RollingStiffness]);
    let u_c = pinned_c.factors[1].ln();
    assert!(
        u_c >= limit_c - 1e-9 && u_c <= limit_c + 0.13,
        "{pinned_c:?}"
    );
    let by_hand = (3.75 * u_c - 1.0).powi(2) / 2.0;
    assert!(
        (pinned_c.chi2 - by_hand).abs() < 0.01,
        "{pinned_c:?} vs {by_hand}"
    );
    let pinned_a = pinned([Effect::NormalDamping, Effect::SurfaceEnergy]);
    assert!(pinned_a.chi2 > 0.6, "{pinned_a:?}");
    assert_eq!(
        reconsider(single, &fits, &pairs),
        Decision::Undetermined {
            singles: vec![Effect::NormalDamping],
            pairs: vec![[Effect::RollingStiffness, Effect::SurfaceEnergy]],
        }
    );
}

fn pair(effects: [Effect; 2], chi2: f64, alone: [f64; 2], pinned: Option<usize>) -> PairFit {
    PairFit {
        effects,
        factors: [2.0, 2.0],
        intervals: [(1.5, 2.5); 2],
        chi2,
        alone,
        on_bound: [false; 2],
        pinned,
        simulated_chi2: Some(chi2),
    }
}

/// The rule on its own: S alone at χ² 5. A pinned partner that improves on S by 2.5 (more
/// than the tie) is a rival; by 1.5, not; a free pair within 2 above S that needs both is a
/// rival; one that beats S by more than χ²₉₅(1) = 3.75 alone is named; two such are tied.
#[test]
fn the_decision_rule_for_pinned_and_free_pairs() {
    let s = Effect::NormalDamping;
    let x = Effect::CriticalRollingLength;
    let (b, c) = (Effect::RollingStiffness, Effect::SurfaceEnergy);
    let fit = EffectFit {
        effect: s,
        factor: 0.5,
        interval: (0.45, 0.55),
        chi2: 5.0,
        explained: 0.9,
        chi2_at_range_ends: (50.0, 50.0),
        confidence: 1.0,
        grid_factors: vec![0.125, 1.0, 4.0],
        bound: None,
        held_out: Vec::new(),
    };
    let fits = [fit];
    let named = Decision::Named(s);
    let undetermined = |pairs: Vec<[Effect; 2]>| Decision::Undetermined {
        singles: vec![s],
        pairs,
    };
    let strong = pair([s, x], 2.5, [5.0, 40.0], Some(1));
    assert_eq!(
        reconsider(named.clone(), &fits, &[strong]),
        undetermined(vec![[s, x]])
    );
    let weak = pair([s, x], 3.5, [5.0, 40.0], Some(1));
    assert_eq!(reconsider(named.clone(), &fits, &[weak]), named);
    let tie = pair([b, c], 6.5, [30.0, 30.0], None);
    assert_eq!(
        reconsider(named.clone(), &fits, &[tie]),
        undetermined(vec![[b, c]])
    );
    let far = pair([b, c], 7.5, [30.0, 30.0], None);
    assert_eq!(reconsider(named.clone(), &fits, &[far]), named);
    let better = pair([b, c], 1.0, [30.0, 30.0], None);
    assert_eq!(
        reconsider(named.clone(), &fits, std::slice::from_ref(&better)),
        Decision::NamedPair([b, c])
    );
    let also = pair([s, x], 1.5, [30.0, 30.0], None);
    assert_eq!(
        reconsider(named, &fits, &[better, also]),
        Decision::Undetermined {
            singles: Vec::new(),
            pairs: vec![[b, c], [s, x]],
        }
    );
}

/// Two curves: a pair fits any two exactly, so none is fitted.
#[test]
fn no_pairs_on_fewer_than_three_curves() {
    let m = MeasuredSet::parse(
        "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e5]\nphi = [0.3, 0.3]\n\
         phi_sigma = 0.01\n[[sticking]]\nvelocity_m_s = 1.0\nsigma_m_s = 0.05\n",
        "t",
    )
    .unwrap();
    let mut g = Grid::new(Effect::RollingStiffness);
    let mut h = Grid::new(Effect::SurfaceEnergy);
    for f in [0.5f64, 1.0, 2.0] {
        let p = vec![
            curves(0.25 + 0.05 * f.ln(), 0.0)[0].clone(),
            curves(0.0, 0.0)[2].clone(),
        ];
        g.insert(f.ln(), p.clone());
        h.insert(f.ln(), p);
    }
    let current = vec![curves(0.25, 0.0)[0].clone(), curves(0.0, 0.0)[2].clone()];
    assert!(fit_pairs(&m, &[g, h], &current, &[], &[]).is_empty());
}
