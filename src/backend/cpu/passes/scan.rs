//! What the contacts pass has to do, found before it does it: the twins of `contacts_scan`,
//! `contacts_pair_tests` and `contacts_clear_tally` in shaders/passes/contacts.wgsl.
//!
//! `contacts_scan` lists each owner with a contact event (a contact to break or one to form,
//! tested exactly as the events test them), a pair contact beyond an inelastic limit (from the
//! pair tests of `integrate_pairs`), or wall contacts (before or after its events), with what
//! the contacts pass does for it. Owners not listed have nothing to do there.

use super::neighbours::{mark_partners, NeighbourList};
use super::prefetching::worthwhile;
use crate::backend::cpu::chunking::{split_len, CHUNK};
use crate::backend::cpu::lanes::ContactLanes;
use crate::backend::cpu::law::integrate_lanes::test_pair_contact;
use crate::backend::cpu::law::wall_planes::{count_touching, touching, WallPlanes};
use crate::backend::cpu::prefetch::{prefetch_one, prefetch_row_ahead, PARTNERS_AHEAD};
use crate::backend::script::{
    OWNER_CORRECTIONS, OWNER_EVENTS, OWNER_WALLS, PAIR_TEST_BEYOND, PAIR_TEST_BREAKS,
};
use crate::model::{wall as wall_law, ContactLaw};
use crate::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
use rayon::prelude::*;

/// Lists the owners with work for the contacts pass into `work` (owner index | `OWNER_*` bits,
/// by ascending owner). Every neighbour pass of the step is done: the list is no longer due.
#[allow(clippy::too_many_arguments)]
pub fn contacts_scan(
    law: &ContactLaw,
    monomers: &Monomers,
    walls: &[Wall],
    list: &mut NeighbourList,
    table: &ContactTable,
    pair_tests: &[u32],
    work: &mut Vec<u32>,
) {
    let n = monomers.len();
    let scan = Scan::new(law, monomers, walls, list, table);
    let rows = RowsFrom::table(table);
    let chunks: Vec<Vec<u32>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .map(|chunk| scan.chunk(&rows, pair_tests, chunk))
        .collect();
    work.clear();
    for c in chunks {
        work.extend(c);
    }
}

/// What the scan of every chunk reads besides the rows.
pub(super) struct Scan<'a> {
    law: &'a ContactLaw,
    monomers: &'a Monomers,
    walls: &'a [Wall],
    list: &'a NeighbourList,
    lanes: ContactLanes,
    planes: WallPlanes,
    prefetching: bool,
}

impl<'a> Scan<'a> {
    /// The scan of this step: the list is no longer due, and its partners are marked.
    pub fn new(
        law: &'a ContactLaw,
        monomers: &'a Monomers,
        walls: &'a [Wall],
        list: &'a mut NeighbourList,
        table: &ContactTable,
    ) -> Scan<'a> {
        list.rebuild_due = false;
        if !list.partners_current {
            mark_partners(list, table);
        }
        Scan {
            law,
            monomers,
            walls,
            list,
            lanes: ContactLanes::chosen(),
            planes: WallPlanes::new(walls),
            prefetching: worthwhile(table),
        }
    }

    /// The neighbour list the scan reads.
    pub fn list(&self) -> &'a NeighbourList {
        self.list
    }

    /// The work items of chunk `chunk`'s owners, by ascending owner (`rows` holds theirs).
    pub fn chunk(&self, rows: &RowsFrom, pair_tests: &[u32], chunk: usize) -> Vec<u32> {
        let (monomers, list) = (self.monomers, self.list);
        let first = chunk * CHUNK;
        let end = (first + CHUNK).min(monomers.len());
        let mut items = Vec::new();
        let mut touching_walls = [0u8; CHUNK];
        let x = &monomers.position[first..end];
        let (law, walls) = (self.law, self.walls);
        count_touching(
            self.lanes,
            walls,
            &self.planes,
            law.radius,
            x,
            &mut touching_walls,
        );
        for i in first..end {
            if self.prefetching {
                // The owner's row (read for its partners) and its candidates' centres.
                let (from, counts) = (rows.pairs_from(first), &rows.pair_counts(first..end));
                prefetch_row_ahead(from, rows.pair_slots, counts, i - first);
                if let Some(ahead) = list.starts.get(i + PARTNERS_AHEAD + 1) {
                    let from = list.starts[i + PARTNERS_AHEAD] as usize;
                    for &(_, j) in &list.pairs[from..*ahead as usize] {
                        prefetch_one(&monomers.position[j as usize]);
                    }
                }
            }
            // The scan no longer reads the rows (marked partners are skipped); this hint
            // brought each row's first line toward the forces pass (12–16 % faster for it).
            // With the forces in the pairs pass, dropping it was no faster (1 thread, φ 0.45).
            if rows.pair_count(i) > 0 {
                prefetch_one(&rows.pairs_from(i)[0]);
            }
            let tests = (pair_tests[i], touching_walls[i - first]);
            if let Some(item) = owner_work(law, monomers, walls, list, rows, tests, i) {
                items.push(item);
            }
        }
        items
    }
}

/// The contact table's rows of the owners from `first` on: the whole table's, or one chunk's
/// (the contacts pass then changing them after the chunk's scan).
pub(super) struct RowsFrom<'a> {
    pub first: usize,
    pub pair_slots: usize,
    pub pair: &'a [PairContact],
    pub pair_count: &'a [u32],
    pub wall_slots: usize,
    pub wall: &'a [WallContact],
    pub wall_count: &'a [u32],
}

impl<'a> RowsFrom<'a> {
    pub fn table(table: &'a ContactTable) -> Self {
        RowsFrom {
            first: 0,
            pair_slots: table.pair_slots,
            pair: &table.pair,
            pair_count: &table.pair_count,
            wall_slots: table.wall_slots,
            wall: &table.wall,
            wall_count: &table.wall_count,
        }
    }

    /// The rows of one chunk's owners from `first` on, with the table's slots per owner.
    pub fn chunk(
        first: usize,
        (pair, pair_count, wall, wall_count): (
            &'a [PairContact],
            &'a [u32],
            &'a [WallContact],
            &'a [u32],
        ),
        (pair_slots, wall_slots): (usize, usize),
    ) -> Self {
        RowsFrom {
            first,
            pair_slots,
            pair,
            pair_count,
            wall_slots,
            wall,
            wall_count,
        }
    }

    fn pairs_from(&self, i: usize) -> &'a [PairContact] {
        &self.pair[(i - self.first) * self.pair_slots..]
    }

    fn pair_count(&self, i: usize) -> u32 {
        self.pair_count[i - self.first]
    }

    fn pair_counts(&self, owners: std::ops::Range<usize>) -> &'a [u32] {
        &self.pair_count[owners.start - self.first..owners.end - self.first]
    }

    fn wall_count(&self, i: usize) -> u32 {
        self.wall_count[i - self.first]
    }

    fn walls_of(&self, i: usize) -> &'a [WallContact] {
        let start = (i - self.first) * self.wall_slots;
        &self.wall[start..start + self.wall_count(i) as usize]
    }

    fn has_pair(&self, i: usize, j: u32) -> bool {
        let row = &self.pairs_from(i)[..self.pair_count(i) as usize];
        row.iter().any(|c| c.partner == j)
    }
}

/// Owner `i`'s work item, if it has work: `tests` are its pair tests and how many walls it
/// touches.
fn owner_work(
    law: &ContactLaw,
    monomers: &Monomers,
    walls: &[Wall],
    list: &NeighbourList,
    table: &RowsFrom,
    (tests, touching_walls): (u32, u8),
    i: usize,
) -> Option<u32> {
    let r = law.radius;
    let pos = &monomers.position;
    let mut event = tests & PAIR_TEST_BREAKS != 0;
    let beyond = tests & PAIR_TEST_BEYOND != 0;
    let mut touching_wall_contacts = 0;
    for c in table.walls_of(i).iter() {
        let w = &walls[c.wall as usize];
        let delta = wall_law::wall_overlap(pos[i], w.point, w.normal, r);
        event |= delta < -w.constants.delta_c;
        touching_wall_contacts += usize::from(touching(delta));
    }
    // Candidates that touch and are not partners yet (the device's lists hold no partners):
    // the marked partners skipped without reading the owner's row (a third of the scan's time
    // was that read and the square root for partners), the table asked for the rest.
    let range = list.starts[i] as usize..list.starts[i + 1] as usize;
    let apart = surely_apart_beyond(2.0 * r);
    let marks = &list.partner[range.clone()];
    let forming = list.pairs[range]
        .iter()
        .zip(marks)
        .any(|(&(_, j), &partner)| {
            let squared = (pos[i] - pos[j as usize]).length_squared();
            !partner
                && may_touch(squared, apart)
                && touching(2.0 * r - squared.sqrt())
                && !table.has_pair(i, j)
        });
    let forms_wall_contact = usize::from(touching_walls) > touching_wall_contacts;
    event |= forming || forms_wall_contact;
    let wall_work = table.wall_count(i) > 0 || forms_wall_contact;
    let bits = if event { OWNER_EVENTS } else { 0 }
        | if beyond { OWNER_CORRECTIONS } else { 0 }
        | if wall_work { OWNER_WALLS } else { 0 };
    (bits != 0).then_some(i as u32 | bits)
}

/// A squared centre distance above which two monomers of contact distance `d` surely do not
/// touch: `d − √s < 0` for every `s` above it, with the rounding of `d²`, of the margin and of
/// the square root (a relative 10⁻¹² is 4500 units in the last place), so the square root the
/// exact test takes is skipped for far candidates without changing a decision. A NaN distance
/// is not above it and goes to the exact test.
fn surely_apart_beyond(d: f64) -> f64 {
    d * d * (1.0 + 1e-12)
}

/// Whether a squared distance is not above `apart` (a NaN is not: it goes to the exact test).
fn may_touch(squared: f64, apart: f64) -> bool {
    squared.partial_cmp(&apart) != Some(std::cmp::Ordering::Greater)
}

/// The tests `integrate_pairs` makes for `contacts_scan`, on the state as it is (positions not
/// advanced): for a state the pairs pass has not seen, such as one just loaded.
pub fn contacts_pair_tests(
    law: &ContactLaw,
    monomers: &Monomers,
    table: &ContactTable,
    pair_tests: &mut Vec<u32>,
) {
    let pos = &monomers.position;
    pair_tests.clear();
    pair_tests.extend((0..monomers.len()).map(|i| {
        table.pairs_of(i).iter().fold(0, |bits, c| {
            bits | test_pair_contact(law, pos[i], pos[c.partner as usize], c)
        })
    }));
}

/// Contacts present at the start are part of the initial state, not a dissipation.
pub fn contacts_clear_tally(tally: &mut Dissipation) {
    *tally = Dissipation::default();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shortcut_for_far_candidates_never_changes_a_decision() {
        // Distances within a few units in the last place of contact, where rounding decides.
        let d = 2.0 * 6e-5;
        let apart = surely_apart_beyond(d);
        let mut s = d * (1.0 - 1e-13);
        let (mut above, mut touching_near) = (0, 0);
        while s < d * (1.0 + 1e-11) {
            for squared in [s * s, (s * s).next_up(), (s * s).next_down()] {
                let exact = touching(d - squared.sqrt());
                touching_near += usize::from(exact);
                if !may_touch(squared, apart) {
                    above += 1;
                    assert!(!exact, "squared distance {squared:e} skipped but touching");
                }
            }
            s = s.next_up().next_up().next_up();
        }
        assert!(above > 0 && touching_near > 0, "both sides were tried");
        assert!(may_touch(f64::NAN, apart), "a NaN goes to the exact test");
    }

    #[test]
    fn touching_counts_zero_and_nan_overlaps() {
        assert!(touching(0.0) && touching(1e-9) && touching(f64::NAN));
        assert!(!touching(-1e-300));
    }
}
