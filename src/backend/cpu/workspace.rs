//! Scratch the CPU passes reuse from step to step: per-slot results, the partner index, and the
//! fixed chunking that makes every sum independent of the thread count.

use super::forces::PairResult;
use super::walls::WallResult;
use crate::state::{ContactTable, Dissipation};
use glam::DVec3;

/// Monomers per unit of parallel work. Sums that leave the monomer loop (dissipation, work) are
/// taken per chunk in monomer order and then over chunks in order: the chunks are fixed by this
/// number, not by the threads, so the bits are the same for any thread count.
pub const CHUNK: usize = 512;

/// Below this many monomers every pass runs on the thread that calls it: handing a pass of a
/// few microseconds to another thread costs about as much as the pass (at N = 1000 two
/// threads were no faster than one). The results do not depend on it.
pub const SERIAL_BELOW: usize = 4096;

/// Least items per parallel split of a pass over `n` monomers whose items hold `unit`
/// monomers each: one chunk's worth, or everything where `n` is below [`SERIAL_BELOW`].
pub fn split_len(n: usize, unit: usize) -> usize {
    if n < SERIAL_BELOW {
        usize::MAX
    } else {
        (CHUNK / unit).max(1)
    }
}

/// Sums per-chunk tallies in chunk order.
pub fn sum_in_order(chunks: &[Dissipation]) -> Dissipation {
    let mut total = Dissipation::default();
    for c in chunks {
        total.add(c);
    }
    total
}

/// Where each owner's contacts sit in the per-contact results (their owners' contacts one
/// after another, in owner and slot order), and for each monomer which of those results it is
/// the partner of, in that order: compressed sparse rows rebuilt after every contact event.
///
/// The results are compact rather than one per slot: at 10⁵ monomers 12 slots of 96 B per
/// owner for about one contact spread 19 MB of results over 115 MB (DESIGN.md, "CPU engine:
/// prefetching contact rows").
#[derive(Clone, Debug, Default)]
pub struct PartnerIndex {
    owner_start: Vec<u32>,
    start: Vec<u32>,
    slots: Vec<u32>,
    /// Fill positions while rebuilding (kept to reuse its allocation).
    next: Vec<u32>,
}

impl PartnerIndex {
    /// Heap bytes of the index's arrays.
    pub fn heap_bytes(&self) -> u64 {
        [&self.owner_start, &self.start, &self.slots, &self.next]
            .iter()
            .map(|v| super::memory::bytes(v))
            .sum()
    }

    /// Rebuilds the index from the table (counting sort by partner; stable in owner order).
    pub fn rebuild(&mut self, table: &ContactTable) {
        let n = table.pair_count.len();
        let ps = table.pair_slots;
        self.owner_start.clear();
        self.owner_start.push(0);
        let mut total = 0;
        for &count in &table.pair_count {
            total += count;
            self.owner_start.push(total);
        }
        self.start.clear();
        self.start.resize(n + 1, 0);
        for i in 0..n {
            for c in &table.pair[i * ps..i * ps + table.pair_count[i] as usize] {
                self.start[c.partner as usize + 1] += 1;
            }
        }
        for j in 0..n {
            self.start[j + 1] += self.start[j];
        }
        self.slots.clear();
        self.slots.resize(self.start[n] as usize, 0);
        self.next.clear();
        self.next.extend_from_slice(&self.start[..n]);
        for i in 0..n {
            for (s, c) in table.pair[i * ps..i * ps + table.pair_count[i] as usize]
                .iter()
                .enumerate()
            {
                let at = &mut self.next[c.partner as usize];
                self.slots[*at as usize] = self.owner_start[i] + s as u32;
                *at += 1;
            }
        }
    }

    /// Positions in the per-contact results whose partner is monomer `j`.
    pub fn of(&self, j: usize) -> &[u32] {
        &self.slots[self.start[j] as usize..self.start[j + 1] as usize]
    }

    /// Where owner `i`'s results begin (`n + 1` entries; the last is the number of contacts).
    pub fn owner_start(&self) -> &[u32] {
        &self.owner_start
    }
}

/// Everything the passes keep between steps besides the state.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    /// One per pair contact, in owner and slot order.
    pub pair_result: Vec<PairResult>,
    pub incoming: PartnerIndex,
    /// Whether `incoming` describes the table as it is: the contacts pass clears it when a
    /// contact forms or breaks (the only changes that move slots).
    pub partner_index_current: bool,
    /// Per wall-contact slot (`i * wall_slots + s`): what the contact exerts.
    pub wall_result: Vec<WallResult>,
    /// Per monomer: the tests of its pair contacts (`PAIR_TEST_*` bits of `backend::script`),
    /// from `integrate_pairs` or `contacts_pair_tests`.
    pub pair_tests: Vec<u32>,
    /// `contacts_scan`'s list: owner index | `OWNER_*` bits, by ascending owner.
    pub work: Vec<u32>,
    /// Per block of `REDUCE_BLOCK` monomers, per wall: the wall forces and their damping parts
    /// summed by `wall_forces`, for `reduce_walls_final`.
    pub wall_partials: Vec<DVec3>,
    pub wall_damping_partials: Vec<DVec3>,
    /// The monomers' damping work of the step, summed by `wall_forces`.
    pub damping_work: f64,
}

impl Workspace {
    /// Makes room for `len` wall-contact results (slots beyond a monomer's count are never
    /// read, so stale values there are harmless).
    pub fn size_wall_results(&mut self, len: usize) {
        self.wall_result.resize(len, WallResult::default());
    }
}
