//! The conservation tests of tests/conservation.rs on the GPU backend: energy and momenta without
//! dissipation, and the energy balance closed by the dissipation tally, with the same states,
//! steps and bounds.

mod common;
mod gpu_support;

use common::*;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::model::{ContactLaw, Damping};
use dustdem::state::Monomers;
use dustdem::state::{DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};

fn gpu_engine(law: ContactLaw, dt: f64, m: Monomers) -> Option<GpuEngine> {
    let ctx = context_for_tests()?;
    Some(
        GpuEngine::new(
            ctx,
            law,
            dt,
            m,
            Vec::new(),
            DEFAULT_PAIR_SLOTS,
            DEFAULT_WALL_SLOTS,
        )
        .unwrap(),
    )
}

#[test]
fn energy_and_momenta_are_conserved_without_dissipation_on_the_gpu() {
    let law = undamped();
    let dt = 1e-10;
    let Some(mut e) = gpu_engine(law, dt, moving_cluster(&law, 0.5, 7)) else {
        return;
    };
    e.readback_every = 1000;
    let s0 = e.snapshot();
    assert_eq!(s0.contacts.pair_contact_count(), 49);
    let e0 = s0.energy();
    let (p0, l0) = (s0.momentum(), s0.angular_momentum());
    let mut worst = 0.0f64;
    for _ in 0..100 {
        e.run(1000).unwrap();
        worst = worst.max((e.energy().mechanical() - e0.mechanical()).abs());
    }
    let end = e.snapshot();
    assert_eq!(end.energy().dissipated.total(), 0.0);
    assert_eq!(end.contacts.pair_contact_count(), 49);
    let rel_total = worst / e0.mechanical().abs();
    eprintln!("GPU: worst |ΔE| over 1e5 steps {worst:.3e} = {rel_total:.2e} of |E|");
    // The CPU reference's bounds (tests/conservation.rs): the device runs the same operations
    // (exact mode) or differs by rounding (relaxed), far below the leap-frog's 3.6e-6.
    assert!(rel_total < 1e-5);
    let dp = (end.momentum() - p0).length() / p0.length();
    let dl = (end.angular_momentum() - l0).length() / l0.length();
    eprintln!("GPU: momentum rel change {dp:.2e}, angular momentum rel change {dl:.2e}");
    assert!(dp < 1e-13);
    assert!(dl < 1e-13);
}

#[test]
fn energy_balance_closes_with_the_dissipation_tally_on_the_gpu() {
    // Twice the measured 3.2e-5 / 1.4e-6, as on the CPU.
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
        let Some(mut e) = gpu_engine(law, dt, moving_cluster(&law, 60.0, 11)) else {
            return;
        };
        e.readback_every = 1000;
        let b0 = e.energy().balance();
        e.run((5e-6 / dt) as u64).unwrap();
        let end = e.energy();
        let d = end.dissipated;
        let error = (end.balance() - b0).abs();
        eprintln!(
            "GPU {name}: dissipated {:.3e} erg; balance error {:.2e} = {:.2e} of dissipated",
            d.total(),
            error,
            error / d.total()
        );
        for channel in [d.damping, d.rolling, d.sliding, d.twisting] {
            assert!(channel > 0.0, "{name}: every channel is exercised: {d:?}");
        }
        assert!(error / d.total() < bound, "{name}");
    }
}
