//! Scratch the CPU passes reuse from step to step: per-slot results, the partner index, and the
//! fixed chunking that makes every sum independent of the thread count.

use super::forces::PairResult;
use super::partner_index::PartnerIndex;
use super::walls::WallResult;
use crate::state::Dissipation;
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

/// Splits `items` into consecutive parts, part `k` from `offsets[k]` to `offsets[k + 1]`
/// (offsets ascending, the first 0): how a parallel pass hands each unit its own stretch of an
/// output laid out by owner or by partner.
pub fn split_at_offsets<T>(
    mut items: &mut [T],
    offsets: impl IntoIterator<Item = usize>,
) -> Vec<&mut [T]> {
    let mut offsets = offsets.into_iter();
    let mut at = offsets.next().unwrap_or(0);
    let mut parts = Vec::new();
    for next in offsets {
        let (part, tail) = items.split_at_mut(next - at);
        parts.push(part);
        items = tail;
        at = next;
    }
    parts
}

/// Sums per-chunk tallies in chunk order.
pub fn sum_in_order(chunks: &[Dissipation]) -> Dissipation {
    let mut total = Dissipation::default();
    for c in chunks {
        total.add(c);
    }
    total
}

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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_run_from_offset_to_offset() {
        let mut items = [1, 2, 3, 4, 5];
        let parts = split_at_offsets(&mut items, [0, 2, 2, 5]);
        let parts: Vec<&[i32]> = parts.into_iter().map(|p| &*p).collect();
        assert_eq!(parts, [&[1, 2][..], &[], &[3, 4, 5]]);
    }
}
