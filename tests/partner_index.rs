//! The CPU engine's partner index kept up to date through the contact events of a run: after
//! every step it lists what a full rebuild from the contact table lists, and the per-contact
//! results the step's pairs pass evaluated and the contacts pass moved are what a full forces
//! pass gives.

use dustdem::backend::cpu::law::results::PairResult;
use dustdem::backend::cpu::partner_index::PartnerIndex;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::script::Kernel;
use dustdem::bench::{benchmark_config, benchmark_engine};
use dustdem::material::Material;
use dustdem::model::{ContactLaw, ModelOptions};
use dustdem::state::Monomers;
use glam::DVec3;

/// Every counted contact's result, owner by owner and slot by slot, as bits.
fn results_by_contact(e: &CpuEngine) -> Vec<String> {
    let start = e.workspace.incoming.owner_start();
    let r: &[PairResult] = &e.workspace.pair_result;
    (0..e.monomers.len())
        .flat_map(|i| {
            let at = start[i] as usize;
            (at..at + e.contacts.pair_count[i] as usize).map(move |k| format!("{:?}", r[k]))
        })
        .collect()
}

/// The step's results against a full forces pass on the state it left (a run of one step
/// ends before any next kick, so positions and velocities are the forces' own).
fn assert_results_of_a_full_forces_pass(e: &CpuEngine) {
    let mut full = e.clone();
    full.run_pass(Kernel::Forces).unwrap();
    assert!(
        results_by_contact(e) == results_by_contact(&full),
        "results at step {}",
        e.step
    );
}

/// Step by step through a fresh sample's first contact events, the index the contacts pass
/// keeps up to date lists what a full rebuild from the table lists.
#[test]
fn the_updated_index_follows_the_table_through_contact_events() {
    let mut e = benchmark_engine(&benchmark_config(1000).unwrap())
        .unwrap()
        .0;
    let (mut updated_steps, n) = (0, e.monomers.len());
    assert!(
        e.workspace.partner_index_current,
        "built by the start's forces"
    );
    for _ in 0..3000 {
        let partners = |e: &CpuEngine| -> Vec<Vec<u32>> {
            (0..n)
                .map(|i| e.contacts.pairs_of(i).iter().map(|c| c.partner).collect())
                .collect()
        };
        let before = partners(&e);
        e.run(1).unwrap();
        if before != partners(&e) && e.workspace.partner_index_current {
            updated_steps += 1;
        }
        let mut fresh = PartnerIndex::default();
        fresh.rebuild(&e.contacts);
        let index = &e.workspace.incoming;
        index.check_layout(&e.contacts).unwrap();
        for j in 0..n {
            let kept: Vec<(usize, usize)> = index.contacts_of_partner(j).collect();
            let rebuilt: Vec<(usize, usize)> = fresh.contacts_of_partner(j).collect();
            assert_eq!(kept, rebuilt, "partner {j} at step {}", e.step);
        }
        assert_results_of_a_full_forces_pass(&e);
    }
    assert!(updated_steps >= 10, "{updated_steps} steps changed rows");
}

fn law() -> ContactLaw {
    ContactLaw::new(&Material::silicate(), &ModelOptions::default())
}

/// Moves the monomers by hand, makes the index current again (as the forces pass does
/// after a change from outside), and takes one step: its contact events go through
/// `update`. Then the index must be what a rebuild gives.
fn step_after_moving(e: &mut CpuEngine, moved: &[(usize, DVec3)]) {
    for &(i, x) in moved {
        e.monomers.position[i] = x;
    }
    e.run_pass(Kernel::Forces).unwrap();
    assert!(e.workspace.partner_index_current);
    e.run(1).unwrap();
    let mut fresh = PartnerIndex::default();
    fresh.rebuild(&e.contacts);
    let kept = &e.workspace.incoming;
    kept.check_layout(&e.contacts).unwrap();
    for j in 0..e.monomers.len() {
        let listed: Vec<(usize, usize)> = kept.contacts_of_partner(j).collect();
        let rebuilt: Vec<(usize, usize)> = fresh.contacts_of_partner(j).collect();
        assert_eq!(listed, rebuilt, "partner {j}");
    }
    assert_results_of_a_full_forces_pass(e);
}

#[test]
fn a_row_that_loses_one_contact_and_gains_another_in_one_step_is_followed() {
    // 0–1 in contact from the start; then 1 pulled away and 2 pushed onto 0: the same
    // count of contacts in 0's row, another partner.
    let r = law().radius;
    let m = Monomers::new(vec![
        DVec3::ZERO,
        DVec3::new(1.99 * r, 0.0, 0.0),
        DVec3::new(0.0, 2.1 * r, 0.0),
    ]);
    let mut e = CpuEngine::new(law(), 1e-10, m, vec![], 12, 3).unwrap();
    assert_eq!(e.contacts.pair_count[0], 1);
    step_after_moving(
        &mut e,
        &[
            (1, DVec3::new(2.15 * r, 0.0, 0.0)),
            (2, DVec3::new(0.0, 1.99 * r, 0.0)),
        ],
    );
    let partners: Vec<u32> = e.contacts.pairs_of(0).iter().map(|c| c.partner).collect();
    assert_eq!(partners, [2], "the events swapped the partner");
}

#[test]
fn contacts_outgrowing_a_monomers_room_in_one_step_rebuild_the_index() {
    // Five monomers around monomer 5, none touching at the start (room 0 + 2), all
    // pushed onto it at once.
    let r = law().radius;
    let around = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z];
    let mut x: Vec<DVec3> = around.iter().map(|d| *d * 2.1 * r).collect();
    x.push(DVec3::ZERO);
    let mut e = CpuEngine::new(law(), 1e-10, Monomers::new(x), vec![], 12, 3).unwrap();
    assert_eq!(e.contacts.pair_contact_count(), 0);
    let pushed: Vec<(usize, DVec3)> = (0..5).map(|i| (i, around[i] * 1.99 * r)).collect();
    step_after_moving(&mut e, &pushed);
    assert_eq!(e.contacts.pair_contact_count(), 5);
}
