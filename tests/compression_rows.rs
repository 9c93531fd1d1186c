//! The compression's row cadence and wall gap, on a box whose plates are placed by hand away
//! from the origin, so the gap, the filling factor and the steps of every row and profile are
//! known without the library.

mod common;

use common::printed::RADIUS;
use dustdem::backend::cpu::CpuEngine;
use dustdem::config::Config;
use dustdem::experiment::compression::{Compression, Event, StopReason};
use dustdem::state::Monomers;
use glam::DVec3;
use std::f64::consts::PI;

const SIDE_UM: f64 = 8.0;
const CM_PER_UM: f64 = 1e-4;

/// Four monomers resting far from each other and from both plates (no contact, no force): the
/// bottom plate at z = 5 µm, the top one 6 µm above it, neither moving; one row every 100
/// steps, a profile every third row, 700 steps.
#[test]
fn rows_and_profiles_come_at_their_steps_with_the_gap_between_the_plates() {
    let config = Config::parse(
        &format!(
            "[sample]\nmonomers = 1\nside_um = {SIDE_UM}\n\
             [experiment]\nkind = \"omni\"\nmax_steps = 700\naverage_steps = 100\n\
             profile_every_rows = 3\n"
        ),
        "cadence",
    )
    .unwrap();
    let (bottom, gap) = (5.0 * CM_PER_UM, 6.0 * CM_PER_UM);
    let centres: Vec<DVec3> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x * 2e-4, y * 2e-4, bottom + 0.5 * gap))
        .collect();
    let mut run = Compression::with_engine(&config, |law, dt, _, mut walls, ps, ws| {
        walls[0].point = DVec3::new(0.0, 0.0, bottom);
        walls[1].point = DVec3::new(0.0, 0.0, bottom + gap);
        walls[1].velocity = DVec3::ZERO;
        CpuEngine::new(law, dt, Monomers::new(centres), walls, ps, ws)
    })
    .unwrap();
    let (mut rows, mut profiles) = (Vec::new(), Vec::new());
    let stop = run
        .run(&mut |e| {
            match e {
                Event::Row(r) => rows.push((r.step, r.wall_gap, r.phi)),
                Event::Profile(r, _) => profiles.push(r.step),
                Event::RowDone(_) => {}
            }
            Ok(())
        })
        .unwrap();
    assert_eq!(stop, StopReason::MaxSteps);
    // What the job prints: the key that stopped the run.
    assert_eq!(stop.to_string(), "max_steps reached");
    let steps: Vec<u64> = rows.iter().map(|r| r.0).collect();
    assert_eq!(steps, [0, 100, 200, 300, 400, 500, 600, 700]);
    // The first row, every third row after it, and the last.
    assert_eq!(profiles, [0, 300, 600, 700]);
    // 4 × (4/3)π r³ over (8 µm)² × 6 µm, by hand with r = 0.6 µm: 0.009 424 8.
    let box_volume = (SIDE_UM * CM_PER_UM).powi(2) * gap;
    let phi = 4.0 * 4.0 / 3.0 * PI * RADIUS.powi(3) / box_volume;
    assert!((phi - 0.009_424_8).abs() < 1e-7, "{phi}");
    for &(step, row_gap, row_phi) in &rows {
        assert!(
            (row_gap - gap).abs() < 1e-12 * gap,
            "step {step}: gap {row_gap}"
        );
        assert!(
            (row_phi / phi - 1.0).abs() < 1e-12,
            "step {step}: φ {row_phi}"
        );
    }
}
