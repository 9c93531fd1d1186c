//! Where each owner's contacts sit in the per-contact results, and for each monomer which of
//! those results it is the partner of: the index `forces` and `wall_forces` gather by.
//!
//! Each monomer keeps the contacts it is the partner of as entries `owner << slot_bits | slot`,
//! ascending (owner and slot order, the gather's order), in `room` places of its own; a
//! result's position is `owner_start[owner] + slot`, the owners' contacts one after another.
//! So a contact event touches only the entries of the partners of the rows it changed
//! ([`PartnerIndex::update`]) and the running totals `owner_start`. Under compression nearly
//! every step has events but few rows change (23 of 10⁴ rows per step at φ 0.45): the full
//! rebuild after each such step had been 7 % of a one-thread step's instructions (DESIGN.md,
//! "CPU engine: the partner index"). The full rebuild remains for a new or replaced table,
//! and for a monomer whose entries outgrow their room.

use crate::state::ContactTable;

/// Spare places per monomer beyond the most entries any monomer had at the full rebuild, so
/// that a contact forming does not force another rebuild at once.
const SPARE_ROOM: usize = 2;

/// An owner's pair row before the contact events changed it: its partners by slot.
#[derive(Clone, Debug, PartialEq)]
pub struct RowChange {
    pub owner: u32,
    pub partners_before: Vec<u32>,
}

/// Per monomer the contacts it is the partner of, and per owner where its results begin.
#[derive(Clone, Debug, Default)]
pub struct PartnerIndex {
    owner_start: Vec<u32>,
    /// Low bits of an entry holding the slot.
    slot_bits: u32,
    /// Places per monomer in `entries`.
    room: usize,
    /// Monomer `j`'s entries are `entries[j * room..j * room + count[j]]`, ascending.
    entries: Vec<u32>,
    count: Vec<u32>,
}

impl PartnerIndex {
    /// Heap bytes of the index's arrays.
    pub fn heap_bytes(&self) -> u64 {
        [&self.owner_start, &self.entries, &self.count]
            .iter()
            .map(|v| super::memory::bytes(v))
            .sum()
    }

    /// Rebuilds the index from the table: the entries counted per partner, the room set by
    /// the most of them, then placed owner by owner and slot by slot (so ascending).
    pub fn rebuild(&mut self, table: &ContactTable) {
        let n = table.pair_count.len();
        let ps = table.pair_slots;
        self.slot_bits = usize::BITS - (ps.max(2) - 1).leading_zeros();
        assert!(
            n <= (u32::MAX >> self.slot_bits) as usize,
            "{n} monomers with {ps} pair slots each do not fit the partner index's 32-bit entries"
        );
        self.count.clear();
        self.count.resize(n, 0);
        for i in 0..n {
            for c in table.pairs_of(i) {
                self.count[c.partner as usize] += 1;
            }
        }
        self.room = self.count.iter().max().map_or(0, |&m| m as usize) + SPARE_ROOM;
        self.count.fill(0);
        self.entries.clear();
        self.entries.resize(n * self.room, 0);
        for i in 0..n {
            for (s, c) in table.pairs_of(i).iter().enumerate() {
                let j = c.partner as usize;
                self.entries[j * self.room + self.count[j] as usize] = self.entry(i, s);
                self.count[j] += 1;
            }
        }
        self.owner_start.clear();
        self.owner_start.push(0);
        let mut total = 0;
        for &count in &table.pair_count {
            total += count;
            self.owner_start.push(total);
        }
    }

    /// Brings the index up to date after contact events changed the rows `changes` lists (by
    /// ascending owner, each with its partners before): the old rows' entries removed, the new
    /// rows' inserted in order, the running totals from the first changed owner on. Returns
    /// false, the index then stale, where a monomer's entries outgrew their room: rebuild it.
    pub fn update(&mut self, table: &ContactTable, changes: &[RowChange]) -> bool {
        for change in changes {
            let i = change.owner as usize;
            for (s, &j) in change.partners_before.iter().enumerate() {
                self.remove(j as usize, self.entry(i, s));
            }
        }
        for change in changes {
            let i = change.owner as usize;
            for (s, c) in table.pairs_of(i).iter().enumerate() {
                if !self.insert(c.partner as usize, self.entry(i, s)) {
                    return false;
                }
            }
        }
        if let Some(first) = changes.first() {
            let start = &mut self.owner_start;
            for i in first.owner as usize..table.pair_count.len() {
                start[i + 1] = start[i] + table.pair_count[i];
            }
        }
        true
    }

    fn entry(&self, owner: usize, slot: usize) -> u32 {
        (owner as u32) << self.slot_bits | slot as u32
    }

    fn remove(&mut self, j: usize, entry: u32) {
        let list = &mut self.entries[j * self.room..j * self.room + self.count[j] as usize];
        let at = list
            .binary_search(&entry)
            .expect("a changed row's old contact is in its partner's entries");
        list.copy_within(at + 1.., at);
        self.count[j] -= 1;
    }

    /// Inserts in order; false where the monomer's room is full.
    fn insert(&mut self, j: usize, entry: u32) -> bool {
        let count = self.count[j] as usize;
        if count == self.room {
            return false;
        }
        let list = &mut self.entries[j * self.room..j * self.room + count + 1];
        let at = list[..count].partition_point(|&e| e < entry);
        list.copy_within(at..count, at + 1);
        list[at] = entry;
        self.count[j] += 1;
        true
    }

    /// Positions in the per-contact results whose partner is monomer `j`, ascending.
    pub fn of(&self, j: usize) -> impl Iterator<Item = u32> + '_ {
        let mask = (1u32 << self.slot_bits) - 1;
        let entries = &self.entries[j * self.room..j * self.room + self.count[j] as usize];
        entries
            .iter()
            .map(move |&e| self.owner_start[(e >> self.slot_bits) as usize] + (e & mask))
    }

    /// Where owner `i`'s results begin (`n + 1` entries; the last is the number of contacts).
    pub fn owner_start(&self) -> &[u32] {
        &self.owner_start
    }
}

#[cfg(test)]
mod tests {
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

    /// The definition: positions counted in owner and slot order, grouped by partner.
    fn defined(t: &ContactTable) -> Vec<Vec<u32>> {
        let n = t.pair_count.len();
        let mut expected = vec![vec![]; n];
        let mut position = 0u32;
        for i in 0..n {
            for c in t.pairs_of(i) {
                expected[c.partner as usize].push(position);
                position += 1;
            }
        }
        expected
    }

    fn assert_defined(index: &PartnerIndex, t: &ContactTable, what: &str) {
        for (j, e) in defined(t).iter().enumerate() {
            assert_eq!(index.of(j).collect::<Vec<_>>(), *e, "partner {j}, {what}");
        }
        let n = t.pair_count.len();
        assert_eq!(
            index.owner_start()[n] as usize,
            t.pair_contact_count(),
            "{what}"
        );
    }

    #[test]
    fn a_small_table_by_hand() {
        // Owner 0: partners 2, 1; owner 1: partner 2; owner 2: none; owner 3: partner 2.
        let rows = [vec![2, 1], vec![2], vec![], vec![2]];
        let mut index = PartnerIndex::default();
        index.rebuild(&table(4, |i| rows[i].clone()));
        assert_eq!(index.owner_start(), [0, 2, 3, 3, 4]);
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
            if !index.update(&t, &changes) {
                // Outgrown: the caller rebuilds.
                index.rebuild(&t);
            }
            assert_defined(&index, &t, &format!("round {round}"));
        }
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
        assert!(!index.update(&t, &changes), "5 entries in a room of 3");
        index.rebuild(&t);
        assert_defined(&index, &t, "rebuilt after outgrowing");
    }
}

#[cfg(test)]
mod event_tests {
    use super::PartnerIndex;
    use crate::backend::cpu::CpuEngine;
    use crate::backend::script::Kernel;
    use crate::material::Material;
    use crate::model::{ContactLaw, ModelOptions};
    use crate::state::Monomers;
    use glam::DVec3;

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
        assert_eq!(e.workspace.incoming.owner_start(), fresh.owner_start());
        for j in 0..e.monomers.len() {
            let kept: Vec<u32> = e.workspace.incoming.of(j).collect();
            assert_eq!(kept, fresh.of(j).collect::<Vec<u32>>(), "partner {j}");
        }
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
}
