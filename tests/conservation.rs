//! Conservation laws of the CPU reference: energy without dissipation, momentum, and the
//! energy balance closed by the dissipation tally.

mod common;

use common::*;
use dustdem::model::Damping;

/// A 50-monomer tree aggregate drifting and spinning as a whole, with random velocities on top.
#[test]
fn energy_and_momenta_are_conserved_without_dissipation() {
    let law = undamped();
    let dt = 1e-10;
    let mut e = engine(law, dt, moving_cluster(&law, 0.5, 7));
    let contacts = e.contacts.pair_contact_count();
    assert_eq!(contacts, 49);
    let e0 = e.energy();
    let (p0, l0) = (e.momentum(), e.angular_momentum());
    let mut worst = 0.0f64;
    for _ in 0..100 {
        e.run(1000).unwrap();
        worst = worst.max((e.energy().mechanical() - e0.mechanical()).abs());
    }
    let end = e.energy();
    assert_eq!(
        end.dissipated.total(),
        0.0,
        "displacements stayed below critical"
    );
    assert_eq!(e.contacts.pair_contact_count(), contacts);
    let rel_total = worst / e0.mechanical().abs();
    let internal_ke = e0.kinetic + e0.rotational;
    eprintln!(
        "E0 {:.4e} erg (kinetic {:.3e}); worst |ΔE| over 1e5 steps {:.3e} = {:.2e} of |E|, {:.2e} of KE",
        e0.mechanical(), internal_ke, worst, rel_total, worst / internal_ke
    );
    // Measured 3.6e-6: the leap-frog's bounded O(dt²) energy error at 100 ps (the stiffest
    // mode, normal, has ω dt = 0.06). Bound 1e-5.
    assert!(rel_total < 1e-5);
    let dp = (e.momentum() - p0).length() / p0.length();
    let dl = (e.angular_momentum() - l0).length() / l0.length();
    eprintln!("momentum rel change {dp:.2e}, angular momentum rel change {dl:.2e}");
    // Pair forces and torques cancel exactly in exact arithmetic; what remains is rounding,
    // measured 1.7e-15 and 1.2e-14 after 1e5 steps. Bound 1e-13.
    assert!(dp < 1e-13);
    assert!(dl < 1e-13);
}

#[test]
fn energy_balance_closes_with_the_dissipation_tally() {
    // Bounds: twice the measured error (3.2e-5 viscous, 1.4e-6 viscoelastic, below).
    for (name, damping, bound) in [
        ("viscous", Damping::Viscous { kappa: 1e-6 }, 6e-5),
        (
            "viscoelastic",
            Damping::Viscoelastic { t_vis: 1.25e-11 },
            3e-6,
        ),
    ] {
        let law = law_with(damping);
        let dt = 2.5e-11;
        // Violent enough to roll, slide, twist inelastically and to break and form contacts; the
        // step resolves 60 cm/s collisions (0.1 δ₀ per step), so what remains is the leap-frog's
        // O(dt²) error (measured: 6.8e-4, 1.2e-4, 3.2e-5 of the dissipated energy at dt = 100,
        // 50, 25 ps).
        let mut e = engine(law, dt, moving_cluster(&law, 60.0, 11));
        let b0 = e.energy().balance();
        e.run((5e-6 / dt) as u64).unwrap();
        let end = e.energy();
        let d = end.dissipated;
        let error = (end.balance() - b0).abs();
        eprintln!(
            "{name}: dissipated {:.3e} erg (break {:.2e}, form {:.2e}, damp {:.2e}, roll {:.2e}, slide {:.2e}, twist {:.2e}); balance error {:.2e} = {:.2e} of dissipated, {:.2e} of |E0|",
            d.total(), d.breaking, d.forming, d.damping, d.rolling, d.sliding, d.twisting, error,
            error / d.total(), error / b0.abs()
        );
        for channel in [d.damping, d.rolling, d.sliding, d.twisting] {
            assert!(channel > 0.0, "{name}: every channel is exercised: {d:?}");
        }
        assert!(error / d.total() < bound, "{name}");
    }
}
