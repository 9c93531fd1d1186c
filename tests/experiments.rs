//! Experiment setups on the CPU reference: unidirectional geometry and overflow detection.

use dustdem::backend::cpu::CpuEngine;
use dustdem::config::Config;
use dustdem::engine::EngineError;
use dustdem::experiment::compression::{Compression, Event, RunError};
use dustdem::experiment::measure::{filling_factor, projected_area};

#[test]
fn unidirectional_run_uses_the_projected_cross_section() {
    let config = Config::parse(
        "[sample]\nmonomers = 300\nfootprint = \"cylinder\"\n[experiment]\nkind = \"uni\"\nwall_speed_m_s = 2.0\nmax_steps = 6000\n",
        "uni test",
    )
    .unwrap();
    let mut run = Compression::with_engine(&config, CpuEngine::new).unwrap();
    assert_eq!(run.engine.walls.len(), 2, "only the two plates");
    let v = 4.0 / 3.0 * std::f64::consts::PI * run.engine.law.radius.powi(3);
    let mut rows = Vec::new();
    run.run(&mut |e| {
        if let Event::Row(r) = e {
            rows.push(*r);
        }
        Ok(())
    })
    .unwrap();
    let last = rows.last().unwrap();
    let area = projected_area(&run.engine.monomers.position, run.engine.law.radius);
    assert_eq!(last.area, area);
    assert!((last.phi - filling_factor(300, v, area, last.wall_gap)).abs() < 1e-15);
    // The projected area is smaller than the cylinder footprint for a porous sample, and the
    // plates approach at 2 m/s.
    assert!(rows[0].area < run.footprint.area());
    assert!((rows[0].wall_gap - last.wall_gap - 200.0 * 6000.0 * 0.3e-9).abs() < 1e-9);
    // The cross-section the run reports on request is the one of its last row (same state),
    // the projected area computed independently above.
    assert_eq!(run.area().unwrap(), area);
}

#[test]
fn contact_slot_overflow_is_an_error_naming_the_setting() {
    let config = Config::parse(
        "[sample]\nmonomers = 400\n[integration]\npair_slots = 1\n",
        "overflow test",
    )
    .unwrap();
    let error = match Compression::with_engine(&config, CpuEngine::new) {
        Err(RunError::Engine(e @ EngineError::SlotOverflow { .. })) => e,
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("an RBD sample has monomers with two partners of higher index"),
    };
    let text = error.to_string();
    assert!(
        text.contains("more than 1 monomer-monomer contact slots") && text.contains("pair_slots"),
        "{text}"
    );
}

#[test]
fn runaway_overlap_and_non_finite_state_are_caught() {
    use dustdem::state::Monomers;
    use glam::DVec3;
    let law = Config::default().contact_law();
    let r = law.radius;
    let squeezed = Monomers::new(vec![DVec3::ZERO, DVec3::new(1.4 * r, 0.0, 0.0)]);
    let engine = CpuEngine::new(law, 1e-10, squeezed, Vec::new(), 12, 3).unwrap();
    let text = engine.check_state().unwrap_err().to_string();
    assert!(
        text.contains("runaway overlap at step 0: monomer 0 and monomer 1"),
        "{text}"
    );
    let mut lost = CpuEngine::new(
        law,
        1e-10,
        Monomers::new(vec![DVec3::ZERO, DVec3::X]),
        Vec::new(),
        12,
        3,
    )
    .unwrap();
    lost.monomers.velocity[1].y = f64::NAN;
    let text = lost.check_state().unwrap_err().to_string();
    assert!(
        text.contains("non-finite position or velocity of monomer 1 at step 0"),
        "{text}"
    );
}
