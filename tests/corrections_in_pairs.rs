//! A CPU run applies the pair contacts' inelastic corrections in `integrate_pairs`
//! (`integrate_pairs_step`), not in the contacts pass, evaluates the forces there too (the
//! forces pass then only for the rows the events changed), runs the contacts scan and the
//! contacts pass in one sweep over the chunks (`contacts_scanned`), and joins each step's kick
//! to the gather of the step before (`wall_forces` with a `NextKick`), unlike the passes run one by one
//! (the device's order). Both give the same state to the bit over a compression with contact
//! events, corrections and wall contacts; the tally's correction channels add the same terms,
//! in another order only within an owner whose contact broke that step.

use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::script::STEP;
use dustdem::config::Config;
use dustdem::experiment::compression::Compression;
use dustdem::state::{simulated_time, PairContact};
use glam::DVec3;

const STEPS: u64 = 1500;

fn engine(tally_corrections: bool) -> CpuEngine {
    let text = format!(
        "[sample]\nmonomers = 3000\nseed = 5\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 10.0\n[output]\ntally_corrections = {tally_corrections}\n"
    );
    let config = Config::parse(&text, "corrections test").unwrap();
    Compression::with_engine(&config, CpuEngine::new)
        .unwrap()
        .engine
}

/// One step with every pass of the script run as the device runs it (`run_pass`), the
/// corrections in the contacts pass.
fn step_pass_by_pass(e: &mut CpuEngine) {
    for pass in STEP {
        e.run_pass(pass).unwrap();
    }
    e.state.step += 1;
    e.state.time = simulated_time(e.state.step, e.state.dt);
}

fn bits(v: &[DVec3]) -> Vec<u64> {
    v.iter()
        .flat_map(|x| x.to_array())
        .map(f64::to_bits)
        .collect()
}

fn pair_bits(row: &[PairContact]) -> Vec<u64> {
    row.iter()
        .flat_map(|c| {
            [
                c.n1.to_array(),
                c.n2.to_array(),
                [c.twist, c.partner as f64, 0.0],
            ]
        })
        .flatten()
        .map(f64::to_bits)
        .collect()
}

fn assert_same_state(a: &CpuEngine, b: &CpuEngine) {
    let (ma, mb) = (&a.monomers, &b.monomers);
    assert!(bits(&ma.position) == bits(&mb.position), "positions");
    assert!(bits(&ma.velocity) == bits(&mb.velocity), "velocities");
    assert!(
        bits(&ma.angular_velocity) == bits(&mb.angular_velocity),
        "spins"
    );
    // Slot for slot up to each count (a slot above it keeps what a contact breaking left there,
    // the last slot's contact before or after its corrections).
    for i in 0..ma.position.len() {
        let (pa, pb) = (a.contacts.pairs_of(i), b.contacts.pairs_of(i));
        assert!(
            pair_bits(pa) == pair_bits(pb),
            "monomer {i}'s pair contacts"
        );
        assert!(
            a.contacts.walls_of(i) == b.contacts.walls_of(i),
            "monomer {i}'s walls"
        );
    }
    assert!(bits(&a.wall_force) == bits(&b.wall_force), "wall forces");
    assert_eq!(a.step, b.step);
}

#[test]
fn the_step_corrects_in_the_pairs_pass_with_the_contacts_pass_bits() {
    let mut fused = engine(true);
    let mut by_pass = fused.clone();
    fused.run(STEPS).unwrap();
    for _ in 0..STEPS {
        step_pass_by_pass(&mut by_pass);
    }
    let (t, u) = (fused.tally, by_pass.tally);
    eprintln!(
        "after {STEPS} steps: {} pair, {} wall contacts; tally {t:?}",
        fused.contacts.pair_contact_count(),
        fused.contacts.wall_contact_count()
    );
    // Contacts broke (the case the order differs in) and every correction booked something.
    assert!(t.breaking != 0.0 && t.rolling != 0.0 && t.sliding != 0.0 && t.twisting != 0.0);
    assert_same_state(&fused, &by_pass);
    // The channels no correction books are the same sums.
    for (a, b) in [
        (t.breaking, u.breaking),
        (t.forming, u.forming),
        (t.damping, u.damping),
        (t.walls, u.walls),
    ] {
        assert_eq!(a.to_bits(), b.to_bits(), "{t:?} against {u:?}");
    }
    // The corrections' sums: the same terms, a few in another order. Each step adds a few
    // hundred terms of one sign, so a reordering moves a sum by a few units in the last place
    // of each step's sum: far below 1e-12 of the total after 1500 steps.
    for (a, b) in [
        (t.rolling, u.rolling),
        (t.sliding, u.sliding),
        (t.twisting, u.twisting),
    ] {
        assert!((a - b).abs() <= 1e-12 * a.abs(), "{a:e} against {b:e}");
    }
}

#[test]
fn unbooked_the_step_still_corrects_in_the_pairs_pass_with_the_same_bits() {
    let mut fused = engine(false);
    let mut by_pass = fused.clone();
    fused.run(500).unwrap();
    for _ in 0..500 {
        step_pass_by_pass(&mut by_pass);
    }
    assert_same_state(&fused, &by_pass);
    assert!(fused.tally.rolling.is_nan() && by_pass.tally.rolling.is_nan());
    assert_eq!(
        fused.tally.forming.to_bits(),
        by_pass.tally.forming.to_bits()
    );
}
