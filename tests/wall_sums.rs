//! The force each wall feels, and its damping part, are the sums of the per-slot wall results
//! over every monomer's wall contacts against that wall. `wall_forces` adds them per block of
//! monomers as it gathers (the run's form joined to the next kick too), `reduce_walls_final`
//! adds the blocks; this test adds the same results plainly, wall by wall, and compares.

use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::script::Kernel;
use dustdem::config::Config;
use dustdem::experiment::compression::Compression;
use glam::DVec3;

fn compressed_engine() -> CpuEngine {
    let text = "[sample]\nmonomers = 3000\nseed = 9\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 10.0\n";
    let config = Config::parse(text, "wall sums test").unwrap();
    let mut e = Compression::with_engine(&config, CpuEngine::new)
        .unwrap()
        .engine;
    e.run(400).unwrap();
    e
}

/// Per wall, the plain sum of `part` of every wall contact's result against it.
fn plain_sums(e: &CpuEngine, part: impl Fn(usize) -> DVec3) -> Vec<DVec3> {
    let ws = e.contacts.wall_slots;
    let mut sums = vec![DVec3::ZERO; e.walls.len()];
    for i in 0..e.monomers.len() {
        for (slot, c) in e.contacts.walls_of(i).iter().enumerate() {
            sums[c.wall as usize] += part(i * ws + slot);
        }
    }
    sums
}

fn assert_close(got: &[DVec3], want: &[DVec3], what: &str) {
    let scale = want.iter().map(|v| v.length()).fold(0.0, f64::max);
    assert!(scale > 0.0, "{what}: some wall is pushed");
    for (w, (g, x)) in got.iter().zip(want).enumerate() {
        // Block sums against one plain sum: a few roundings of the largest sum apart.
        assert!(
            (*g - *x).length() <= 1e-12 * scale,
            "{what} of wall {w}: {g} against {x}"
        );
    }
}

#[test]
fn each_wall_feels_the_sum_of_its_contacts_results_and_their_damping() {
    let mut e = compressed_engine();
    assert!(e.contacts.wall_contact_count() > 50, "walls in contact");
    // Every wall contact's damping part is not zero: the damping sums cannot pass as forces.
    e.run_pass(Kernel::WallForces).unwrap();
    e.run_pass(Kernel::ReduceWallsFinal).unwrap();
    let results = &e.workspace.wall_result;
    let force = plain_sums(&e, |s| results[s].force);
    let damping = plain_sums(&e, |s| results[s].damping);
    assert_close(&e.wall_force, &force, "force");
    assert_close(&e.wall_damping, &damping, "damping");
    let differ = force
        .iter()
        .zip(&damping)
        .any(|(f, d)| (*f - *d).length() > 0.0);
    assert!(differ, "the damping parts differ from the forces");
}
