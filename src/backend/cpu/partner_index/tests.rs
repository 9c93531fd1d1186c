//! The partner index against its definition, through rebuilds and contact events.

use super::*;
use crate::state::PairContact;

const SLOTS: usize = 4;

/// A table of `n` monomers whose owner `i` has partners `partners(i)`.
fn table(n: usize, partners: impl Fn(usize) -> Vec<u32>) -> ContactTable {
    let mut t = ContactTable::new(n, SLOTS, 1);
    for i in 0..n {
        set_row(&mut t, i, &partners(i));
    }
    t
}

fn set_row(t: &mut ContactTable, i: usize, partners: &[u32]) {
    for (s, &j) in partners.iter().enumerate() {
        t.pair[i * SLOTS + s] = PairContact {
            partner: j,
            ..t.pair[i * SLOTS + s]
        };
    }
    t.pair_count[i] = partners.len() as u32;
}

/// The definition: every contact (owner, slot) grouped by partner, in owner and slot
/// order.
fn defined(t: &ContactTable) -> Vec<Vec<(usize, usize)>> {
    let n = t.pair_count.len();
    let mut expected = vec![vec![]; n];
    for i in 0..n {
        for (s, c) in t.pairs_of(i).iter().enumerate() {
            expected[c.partner as usize].push((i, s));
        }
    }
    expected
}

/// The index lists the definition's contacts per partner, its positions are the owners'
/// starts plus the slot, and the starts lay the owners out one after another per chunk.
fn assert_defined(index: &PartnerIndex, t: &ContactTable, what: &str) {
    index
        .check_layout(t)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let start = index.owner_start();
    for (j, e) in defined(t).iter().enumerate() {
        let listed: Vec<(usize, usize)> = index.contacts_of_partner(j).collect();
        assert_eq!(listed, *e, "partner {j}, {what}");
        let positions: Vec<u32> = e.iter().map(|&(i, s)| start[i] + s as u32).collect();
        assert_eq!(index.of(j).collect::<Vec<_>>(), positions, "{what}");
    }
}

#[test]
fn a_small_table_by_hand() {
    // Owner 0: partners 2, 1; owner 1: partner 2; owner 2: none; owner 3: partner 2.
    let rows = [vec![2, 1], vec![2], vec![], vec![2]];
    let mut index = PartnerIndex::default();
    index.rebuild(&table(4, |i| rows[i].clone()));
    // One chunk of 4 contacts, then its 4 / 8 + 8 spare places.
    assert_eq!(index.owner_start(), [0, 2, 3, 3, 12]);
    let of: Vec<Vec<u32>> = (0..4).map(|j| index.of(j).collect()).collect();
    assert_eq!(of, [vec![], vec![1], vec![0, 2, 3], vec![]]);
    // Room 3 + 2 spare places for 4 monomers, their counts, 5 owner starts: 29 × 4 B.
    assert!(index.heap_bytes() >= 116, "{} B", index.heap_bytes());
}

fn scattered(n: usize, seed: usize) -> impl Fn(usize) -> Vec<u32> {
    move |i: usize| {
        let k = (i * 7919 + 13 + seed) % (SLOTS + 1);
        (1..=k)
            .map(|s| ((i * 104_729 + s * 7_727 + seed * 31) % n) as u32)
            .collect()
    }
}

#[test]
fn a_rebuilt_index_is_the_index_of_the_definition() {
    let n = 5000;
    let t = table(n, scattered(n, 0));
    let mut index = PartnerIndex::default();
    index.rebuild(&t);
    assert_defined(&index, &t, "rebuilt");
}

#[test]
fn rows_changed_by_events_update_the_index_to_the_definition() {
    let n = 700;
    let mut t = table(n, scattered(n, 0));
    let mut index = PartnerIndex::default();
    index.rebuild(&t);
    // Per result: the owner and partner of its contact, as a forces pass would leave it.
    let laid_out = |index: &PartnerIndex, t: &ContactTable| {
        let mut results = vec![(u32::MAX, u32::MAX); index.owner_start()[n] as usize];
        for i in 0..n {
            for (s, c) in t.pairs_of(i).iter().enumerate() {
                results[index.owner_start()[i] as usize + s] = (i as u32, c.partner);
            }
        }
        results
    };
    let (mut results, mut kept_rounds) = (laid_out(&index, &t), 0);
    for round in 1..40 {
        // Some rows lose a contact, gain one, or both (by ascending owner).
        let owners: Vec<usize> = (0..n).filter(|i| (i * 31 + round * 17) % 97 == 0).collect();
        let mut changes = vec![];
        for &i in &owners {
            let before: Vec<u32> = t.pairs_of(i).iter().map(|c| c.partner).collect();
            let mut after = before.clone();
            if round % 3 != 1 && !after.is_empty() {
                after.swap_remove((i + round) % after.len());
            }
            if round % 3 != 2 && after.len() < SLOTS {
                after.push(((i * 13 + round * 101) % n) as u32);
            }
            set_row(&mut t, i, &after);
            changes.push(RowChange {
                owner: i as u32,
                partners_before: before,
            });
        }
        if index.update(&t, &changes, &mut results) {
            // The unchanged rows' results stay where they were; the changed ones are
            // evaluated into their places.
            results.resize(index.owner_start()[n] as usize, (u32::MAX, u32::MAX));
            for &i in &owners {
                for (s, c) in t.pairs_of(i).iter().enumerate() {
                    results[index.owner_start()[i] as usize + s] = (i as u32, c.partner);
                }
            }
            let start = index.owner_start();
            for i in 0..n {
                let at = start[i] as usize;
                let live = &results[at..at + t.pair_count[i] as usize];
                let expected: Vec<(u32, u32)> = t
                    .pairs_of(i)
                    .iter()
                    .map(|c| (i as u32, c.partner))
                    .collect();
                assert!(live == expected, "round {round}, owner {i}: {live:?}");
            }
            kept_rounds += 1;
        } else {
            // Outgrown: the caller rebuilds.
            index.rebuild(&t);
            results = laid_out(&index, &t);
        }
        assert_defined(&index, &t, &format!("round {round}"));
    }
    assert!(kept_rounds > 20, "{kept_rounds} rounds kept the results");
}

#[test]
fn rows_growing_past_the_spare_places_lay_their_chunk_out_again() {
    // One chunk of 64 one-contact rows (16 spare places), every eighth growing by one
    // contact per round: round 1 takes the spare places, round 2 finds none left but
    // fits once the chunk is laid out afresh, results moving along.
    let n = 64;
    let mut t = table(n, |i| vec![((i + 1) % n) as u32]);
    let mut index = PartnerIndex::default();
    index.rebuild(&t);
    let end = index.owner_start()[n];
    let mut results = vec![u32::MAX; end as usize];
    let place = |index: &PartnerIndex, i: usize, s: usize| index.owner_start()[i] as usize + s;
    for i in 0..n {
        results[place(&index, i, 0)] = (i * 100) as u32;
    }
    for round in 1..=2 {
        // Rows 0, 8, 16, .. gain a contact (by ascending owner).
        let mut changes = vec![];
        for i in (0..n).step_by(8) {
            let before: Vec<u32> = t.pairs_of(i).iter().map(|c| c.partner).collect();
            let mut after = before.clone();
            after.push(((i + 1 + round) % n) as u32);
            set_row(&mut t, i, &after);
            changes.push(RowChange {
                owner: i as u32,
                partners_before: before,
            });
        }
        assert!(index.update(&t, &changes, &mut results), "round {round}");
        assert_defined(&index, &t, &format!("round {round}"));
        let start = index.owner_start();
        let one_after_another = (1..n).all(|i| start[i] == start[i - 1] + t.pair_count[i - 1]);
        assert_eq!(
            one_after_another,
            round == 2,
            "laid out afresh in round 2 only"
        );
        for i in (0..n).filter(|i| i % 8 != 0) {
            assert_eq!(results[place(&index, i, 0)], (i * 100) as u32, "owner {i}");
        }
        for i in (0..n).step_by(8) {
            for s in 0..t.pair_count[i] as usize {
                results[place(&index, i, s)] = (i * 100 + s) as u32;
            }
        }
    }
    assert_eq!(index.owner_start()[n], end, "within its stretch");
}

#[test]
fn a_monomer_outgrowing_its_room_asks_for_a_rebuild() {
    // Monomer 0 is the partner of one contact; room 1 + 2 spare.
    let mut t = table(6, |i| if i == 1 { vec![0] } else { vec![] });
    let mut index = PartnerIndex::default();
    index.rebuild(&t);
    let mut changes = vec![];
    for i in 2..6 {
        set_row(&mut t, i, &[0]);
        changes.push(RowChange {
            owner: i as u32,
            partners_before: vec![],
        });
    }
    let mut results: Vec<u32> = vec![];
    assert!(
        !index.update(&t, &changes, &mut results),
        "5 entries in a room of 3"
    );
    index.rebuild(&t);
    assert_defined(&index, &t, "rebuilt after outgrowing");
}
