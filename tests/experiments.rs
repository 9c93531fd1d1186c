//! Experiment setups on the CPU reference: unidirectional geometry and overflow detection.

use dustdem::config::Config;
use dustdem::cpu::EngineError;
use dustdem::experiment::compression::{Compression, Event, RunError};
use dustdem::experiment::measure::{filling_factor, projected_area};

#[test]
fn unidirectional_run_uses_the_projected_cross_section() {
    let config = Config::parse(
        "[sample]\nmonomers = 300\nfootprint = \"cylinder\"\n[experiment]\nkind = \"uni\"\nwall_speed_m_s = 2.0\nmax_steps = 6000\n",
        "uni test",
    )
    .unwrap();
    let mut run = Compression::new(&config).unwrap();
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
    assert!(rows[0].area < run.sample.footprint.area());
    assert!((rows[0].wall_gap - last.wall_gap - 200.0 * 6000.0 * 0.3e-9).abs() < 1e-9);
}

#[test]
fn contact_slot_overflow_is_an_error_naming_the_setting() {
    let config = Config::parse(
        "[sample]\nmonomers = 400\n[integration]\npair_slots = 1\n",
        "overflow test",
    )
    .unwrap();
    let error = match Compression::new(&config) {
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
