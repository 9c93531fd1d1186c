//! The CPU engine's partner index kept up to date through the contact events of a run: after
//! every step it lists what a full rebuild from the contact table lists.

use dustdem::backend::cpu::partner_index::PartnerIndex;
use dustdem::backend::cpu::CpuEngine;
use dustdem::bench::{benchmark_config, benchmark_engine};

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
        assert_eq!(e.workspace.incoming.owner_start(), fresh.owner_start());
        for j in 0..n {
            let (kept, rebuilt): (Vec<u32>, Vec<u32>) =
                (e.workspace.incoming.of(j).collect(), fresh.of(j).collect());
            assert_eq!(kept, rebuilt, "partner {j} at step {}", e.step);
        }
    }
    assert!(updated_steps >= 10, "{updated_steps} steps changed rows");
}
