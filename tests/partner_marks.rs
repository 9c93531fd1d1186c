//! The contacts scan skips the candidate pairs marked as contacts of the table (the device's
//! candidate lists hold no partners). The marks follow the table through contact events and
//! list rebuilds: after every step of a compression in which contacts form and break, each
//! mark says what the table says.

use dustdem::backend::cpu::CpuEngine;
use dustdem::config::Config;
use dustdem::experiment::compression::Compression;

/// A CPU engine set up for an omnidirectional compression at 10 m/s of `monomers`.
fn compression(monomers: usize, seed: u64) -> CpuEngine {
    let text = format!(
        "[sample]\nmonomers = {monomers}\nseed = {seed}\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 10.0\n"
    );
    let config = Config::parse(&text, "marks test").unwrap();
    Compression::with_engine(&config, CpuEngine::new)
        .unwrap()
        .engine
}

#[test]
fn the_marks_say_which_candidates_are_contacts_after_every_step() {
    let mut e = compression(3000, 5);
    let (mut checked, mut rebuilds, mut changes) = (0, 0, 0);
    let mut contacts = e.contacts.pair_contact_count();
    let mut reference = e.neighbours.reference.clone();
    for _ in 0..1500 {
        e.step().unwrap();
        let list = &e.neighbours;
        rebuilds += usize::from(list.reference != reference);
        reference.clone_from(&list.reference);
        let now = e.contacts.pair_contact_count();
        changes += usize::from(now != contacts);
        contacts = now;
        assert!(list.partners_current, "the scan marked the list");
        assert_eq!(list.partner.len(), list.pairs.len());
        for (&(i, j), &marked) in list.pairs.iter().zip(&list.partner) {
            assert_eq!(
                marked,
                e.contacts.has_pair(i as usize, j),
                "step {}: pair ({i}, {j})",
                e.step
            );
            checked += 1;
        }
    }
    eprintln!("{checked} marks checked; {rebuilds} rebuilds, {changes} steps with contacts formed or broken");
    assert!(rebuilds > 2 && changes > 100);
}

#[test]
fn a_table_changed_from_outside_is_marked_again_before_the_next_scan() {
    let mut e = compression(300, 2);
    e.run(10).unwrap();
    let i = (0..e.monomers.len())
        .find(|&i| !e.contacts.pairs_of(i).is_empty())
        .unwrap();
    // A contact removed through the engine's state: its pair must be a candidate again.
    e.contacts.pair_count[i] -= 1;
    assert!(!e.neighbours.partners_current);
    e.step().unwrap();
    let list = &e.neighbours;
    for (&(i, j), &marked) in list.pairs.iter().zip(&list.partner) {
        assert_eq!(marked, e.contacts.has_pair(i as usize, j));
    }
}
