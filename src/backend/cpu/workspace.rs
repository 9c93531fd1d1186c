//! What the passes hand each other and keep from step to step: per-slot results, the
//! partner index, work lists and partial sums (the passes' results; the chunking they share
//! is chunking.rs).

use super::law::results::{PairResult, WallResult};
use super::memory::bytes;
use super::partner_index::PartnerIndex;
use glam::DVec3;

/// Everything the passes keep between steps besides the state.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    /// One per pair contact, owner `i`'s slot `s` at `incoming.owner_start()[i] + s`.
    pub pair_result: Vec<PairResult>,
    pub incoming: PartnerIndex,
    /// Whether `incoming` describes the table as it is: the contacts pass clears it when a
    /// contact forms or breaks (the only changes that move slots).
    pub partner_index_current: bool,
    /// Whether `pair_result` holds the forces the step's pairs pass evaluated
    /// (`integrate_pairs_step`), moved by the contacts pass with the rows its events left
    /// alone; the step's `forces` then evaluates only `changed_rows`.
    pub results_of_step: bool,
    /// The owners whose pair rows this step's contact events changed, ascending.
    pub changed_rows: Vec<u32>,
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

    /// Heap bytes of its arrays (their capacities).
    pub fn heap_bytes(&self) -> u64 {
        bytes(&self.pair_result)
            + self.incoming.heap_bytes()
            + bytes(&self.wall_result)
            + bytes(&self.pair_tests)
            + bytes(&self.work)
            + bytes(&self.wall_partials)
            + bytes(&self.wall_damping_partials)
    }
}
