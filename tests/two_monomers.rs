//! Two-monomer physics on the CPU reference: sticking, pull-off, oscillation periods.

mod common;

use common::*;
use dustdem::experiment::collision::*;
use dustdem::material::{normal_period, sliding_period, Derived, Material, TwistingStiffness};
use dustdem::model::normal::{jkr_force, D_MIN, X_MIN};
use dustdem::model::{ContactLaw, Damping, ModelOptions};
use glam::DVec3;

#[test]
fn sticking_threshold_equals_the_jkr_loop_energy_balance() {
    let law = undamped();
    let analytic = analytic_sticking_speed(&law);
    // Derived from the force law: E_loop = 0.772241 F_c δ₀ → 11.0 cm/s (Chokshi: 7.18 cm/s).
    assert!(
        (analytic - 11.0).abs() < 0.1,
        "analytic threshold {analytic}"
    );
    let dt = 2e-12;
    assert_eq!(
        head_on_collision(&law, 0.5 * analytic, dt, 5.0)
            .unwrap()
            .outcome,
        Outcome::Stuck
    );
    assert!(matches!(
        head_on_collision(&law, 2.0 * analytic, dt, 5.0)
            .unwrap()
            .outcome,
        Outcome::Separated { .. }
    ));
    let simulated = sticking_threshold(&law, dt, 0.5 * analytic, 2.0 * analytic, 1e-3).unwrap();
    let rel = simulated / analytic - 1.0;
    eprintln!("sticking threshold: simulated {simulated:.4} cm/s, analytic {analytic:.4} cm/s, rel {rel:.2e}");
    assert!(rel.abs() < 0.03);
}

#[test]
fn damping_raises_the_sticking_threshold() {
    let dt = 2e-12;
    let base = analytic_sticking_speed(&undamped());
    let viscous = sticking_threshold(
        &law_with(Damping::Viscous { kappa: 1e-6 }),
        dt,
        0.5 * base,
        3.0 * base,
        1e-3,
    )
    .unwrap();
    let visco = law_with(Damping::Viscoelastic { t_vis: 1.25e-11 });
    let viscoelastic = sticking_threshold(&visco, dt, base, 200.0 * base, 1e-3).unwrap();
    eprintln!("thresholds: none {base:.3} cm/s, kappa=1e-6 {viscous:.3} cm/s, T_vis=1.25e-11 {viscoelastic:.3} cm/s");
    assert!(viscous > base);
    assert!(viscoelastic > 2.0 * viscous);
}

#[test]
fn slow_pull_apart_peaks_at_f_c_and_breaks_at_minus_delta_c() {
    let law = undamped();
    let k = law.pair;
    let dt = 1e-11;
    let mut monomers = pair_at_overlap(&law, k.delta0);
    // Monomer 0 held, monomer 1 pulled away slowly (driven, no inertia).
    monomers.inverse_mass_scale = vec![0.0, 0.0];
    monomers.inverse_inertia_scale = vec![0.0, 0.0];
    let speed = 1e-3 * k.delta0 / dt / 100.0; // 10^-5 δ₀ per step
    monomers.velocity[1] = DVec3::new(speed, 0.0, 0.0);
    let mut e = engine(law, dt, monomers);
    let mut max_tension: f64 = 0.0;
    let mut last_overlap = f64::NAN;
    while e.contacts.pair_contact_count() > 0 {
        last_overlap =
            2.0 * law.radius - (e.monomers.position[1] - e.monomers.position[0]).length();
        max_tension = max_tension.max(-e.monomers.force[1].x);
        e.step().unwrap();
    }
    let rel_fc = max_tension / k.f_c - 1.0;
    eprintln!("pull-apart: max tension {max_tension:.6e} dyn vs F_c {:.6e} ({rel_fc:.2e}); last overlap {:.6} δ_c", k.f_c, last_overlap / k.delta_c);
    assert!(rel_fc.abs() < 0.005);
    let broken_at = 2.0 * law.radius - (e.monomers.position[1] - e.monomers.position[0]).length();
    assert!(last_overlap >= -k.delta_c && broken_at < -k.delta_c);
    assert!((broken_at + k.delta_c).abs() < 2.0 * speed * dt);
    // Force at the break: the stable-branch end value −5/9 F_c.
    assert!((jkr_force(X_MIN, k.f_c) / k.f_c + 5.0 / 9.0).abs() < 1e-12);
    assert!((D_MIN * k.delta0 + k.delta_c).abs() < 1e-12 * k.delta_c);
}

#[test]
fn normal_oscillation_period_matches_physics_md() {
    let law = undamped();
    let dt = 5e-12;
    let mut e = engine(law, dt, pair_at_overlap(&law, 1.02 * law.pair.delta0));
    let (mut t, mut y) = (Vec::new(), Vec::new());
    for _ in 0..20_000 {
        e.step().unwrap();
        t.push(e.time);
        y.push(e.monomers.position[1].x - e.monomers.position[0].x);
    }
    let mean = 2.0 * law.radius - law.pair.delta0;
    let period = mean_period(&upward_crossings(&t, &y, mean));
    let expected = normal_period(&Derived::new(
        &Material::silicate(),
        TwistingStiffness::Printed,
    ));
    eprintln!("normal period {period:.4e} s, physics.md {expected:.4e} s");
    assert!((period / expected - 1.0).abs() < 0.03);
}

/// Sliding: monomer 0 held; monomer 1 may translate but not rotate, displaced tangentially, so
/// the only restoring force is k_s ζ and the period is 2π√(m/(m_s k_s)).
fn sliding_oscillation_period(modifier: f64) -> f64 {
    let options = ModelOptions {
        damping: Damping::None,
        sliding_modifier: modifier,
        ..ModelOptions::default()
    };
    let law = ContactLaw::new(&Material::silicate(), &options);
    let dt = 5e-12;
    let mut monomers = pair_at_overlap(&law, law.pair.delta0);
    monomers.inverse_mass_scale[0] = 0.0;
    monomers.inverse_inertia_scale = vec![0.0, 0.0];
    let mut e = engine(law, dt, monomers);
    // Tangential kick well inside ζ_crit.
    e.monomers.velocity[1] = DVec3::new(0.0, 2.0, 0.0);
    let (mut t, mut y) = (Vec::new(), Vec::new());
    for _ in 0..30_000 {
        e.step().unwrap();
        t.push(e.time);
        y.push(e.monomers.position[1].y);
    }
    assert_eq!(e.tally.sliding, 0.0, "stayed elastic");
    mean_period(&upward_crossings(&t, &y, 0.0))
}

#[test]
fn sliding_periods_match_physics_md() {
    let d = Derived::new(&Material::silicate(), TwistingStiffness::Printed);
    for modifier in [1.0, 2.5] {
        let period = sliding_oscillation_period(modifier);
        let expected = sliding_period(&d, modifier);
        eprintln!("sliding period m_s={modifier}: {period:.4e} s, physics.md {expected:.4e} s");
        assert!((period / expected - 1.0).abs() < 0.03);
    }
    assert!((normal_period(&d) - 10.77e-9).abs() < 0.01e-9);
}
