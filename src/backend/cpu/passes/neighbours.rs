//! Candidate pairs for contact detection: a cell grid rebuilt only when some monomer has moved
//! more than half the skin (Verlet list), so the cost per step stays O(N) with a small constant.
//!
//! Cells are keyed by integer coordinates and found by sorting, so the domain is unbounded
//! (unidirectional runs spread sideways) and the memory is proportional to N.
//!
//! The twins of shaders/passes/neighbours.wgsl: [`neighbours`] puts every monomer in its cell,
//! [`neighbours_list`] lists the pairs within reach from the 27 cells around each, both only
//! when `integrate_drift` found the list due. The device hashes cells into a bucket table of
//! fixed size and keeps each monomer's candidates without its current partners (its lists
//! have a capacity); the CPU sorts cell keys and keeps one sorted list of all pairs, partners
//! included (the contacts pass skips them): the same candidates.

use crate::backend::cpu::chunking::{split_at_offsets, split_len, CHUNK};
use crate::backend::cpu::memory::bytes;
use crate::state::ContactTable;
use glam::DVec3;
use rayon::prelude::*;

#[derive(Clone, Debug, PartialEq)]
pub struct NeighbourList {
    /// Centre distance below which a pair can touch (2r).
    pub contact_distance: f64,
    /// Extra distance included so the list stays valid while monomers move.
    pub skin: f64,
    /// Candidate pairs (i < j), sorted.
    pub pairs: Vec<(u32, u32)>,
    /// Where each monomer's candidates start in `pairs` (n + 1 entries; see [`owner_starts`]).
    pub starts: Vec<u32>,
    /// The positions the list was built from.
    pub reference: Vec<DVec3>,
    /// Some monomer has moved more than half the skin since `reference` (or there is none):
    /// the neighbour passes rebuild the list.
    pub rebuild_due: bool,
    /// Every monomer by its cell (edge `contact_distance + skin`), sorted: `neighbours`' bins.
    pub cells: Vec<([i64; 3], u32)>,
    /// Per pair, whether it is a contact of the table (`partner[k]` for `pairs[k]`), where
    /// `partners_current`: the scan then skips these without reading the owner's row, as the
    /// device's lists hold no partners ([`mark_partners`], [`mark_partners_of`]).
    pub partner: Vec<bool>,
    /// Whether `partner` matches the contact table: false from a rebuild (or a table changed
    /// from outside) until the scan marks the pairs again.
    pub partners_current: bool,
}

impl NeighbourList {
    /// Heap bytes of its arrays (their capacities), as `memory.rs` counts the state's.
    pub fn heap_bytes(&self) -> u64 {
        bytes(&self.pairs) + bytes(&self.starts) + bytes(&self.reference) + bytes(&self.cells)
    }

    pub fn new(contact_distance: f64, skin: f64) -> Self {
        NeighbourList {
            contact_distance,
            skin,
            pairs: Vec::new(),
            starts: Vec::new(),
            reference: Vec::new(),
            rebuild_due: true,
            cells: Vec::new(),
            partner: Vec::new(),
            partners_current: false,
        }
    }

    /// Builds the list from `position` now (the neighbour passes, due or not).
    pub fn build(&mut self, position: &[DVec3]) {
        self.rebuild_due = true;
        neighbours(position, self);
        neighbours_list(position, self);
        self.rebuild_due = false;
    }
}

/// Puts every monomer in its cell of edge `contact_distance + skin` (sorted by cell), when
/// the list is due.
pub fn neighbours(position: &[DVec3], list: &mut NeighbourList) {
    if !list.rebuild_due {
        return;
    }
    let cutoff = list.contact_distance + list.skin;
    list.cells = position
        .par_iter()
        .enumerate()
        .map(|(i, p)| (cell_of(*p, cutoff), i as u32))
        .collect();
    list.cells.par_sort_unstable();
}

/// The candidate pairs from the cells around each monomer, when the list is due; the positions
/// they were found at become the reference of `integrate_drift`'s test.
pub fn neighbours_list(position: &[DVec3], list: &mut NeighbourList) {
    if !list.rebuild_due {
        return;
    }
    list.pairs = pairs_from_cells(position, &list.cells, list.contact_distance + list.skin);
    list.starts = owner_starts(&list.pairs, position.len());
    list.partners_current = false;
    list.reference.clear();
    list.reference.extend_from_slice(position);
}

/// Marks every pair of the list that is a contact of `table` (`list.partner`), owner by owner
/// in parallel.
pub fn mark_partners(list: &mut NeighbourList, table: &ContactTable) {
    let n = list.starts.len().saturating_sub(1);
    let mut marks = std::mem::take(&mut list.partner);
    marks.clear();
    marks.resize(list.pairs.len(), false);
    let (pairs, starts) = (&list.pairs, &list.starts);
    let split = split_at_offsets(
        &mut marks,
        (0..=n.div_ceil(CHUNK)).map(|c| starts[(c * CHUNK).min(n)] as usize),
    );
    split
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .for_each(|(chunk, marks)| {
            let from = starts[(chunk * CHUNK).min(n)] as usize;
            for (mark, &(i, j)) in marks.iter_mut().zip(&pairs[from..]) {
                *mark = table.has_pair(i as usize, j);
            }
        });
    list.partner = marks;
    list.partners_current = true;
}

/// Marks owner `i`'s pairs again after its contacts changed.
pub fn mark_partners_of(list: &mut NeighbourList, table: &ContactTable, i: usize) {
    let range = list.starts[i] as usize..list.starts[i + 1] as usize;
    for (mark, &(_, j)) in list.partner[range.clone()]
        .iter_mut()
        .zip(&list.pairs[range])
    {
        *mark = table.has_pair(i, j);
    }
}

/// For pairs sorted by owner, the index of each owner's first pair (n + 1 entries, the last
/// one the number of pairs): owner i's pairs are `pairs[starts[i]..starts[i + 1]]`.
pub fn owner_starts(pairs: &[(u32, u32)], n: usize) -> Vec<u32> {
    let mut starts = vec![0u32; n + 1];
    for &(i, _) in pairs {
        starts[i as usize + 1] += 1;
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    starts
}

fn cell_of(p: DVec3, cell: f64) -> [i64; 3] {
    [
        (p.x / cell).floor() as i64,
        (p.y / cell).floor() as i64,
        (p.z / cell).floor() as i64,
    ]
}

/// All pairs (i < j) closer than `cutoff` from the monomers sorted by cell (edge `cutoff`).
/// Each monomer's partners are found in parallel and sorted; the lists are joined in monomer
/// order, so the result is the same for any thread count.
fn pairs_from_cells(position: &[DVec3], keyed: &[([i64; 3], u32)], cutoff: f64) -> Vec<(u32, u32)> {
    let cutoff2 = cutoff * cutoff;
    let lists: Vec<Vec<(u32, u32)>> = position
        .par_chunks(CHUNK)
        .with_min_len(split_len(position.len(), CHUNK))
        .enumerate()
        .map(|(chunk, points)| {
            let mut pairs = Vec::new();
            for (k, p) in points.iter().enumerate() {
                let i = chunk * CHUNK + k;
                let first = pairs.len();
                let c = cell_of(*p, cutoff);
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                            let start = keyed.partition_point(|(k, _)| *k < key);
                            for &(k, j) in &keyed[start..] {
                                if k != key {
                                    break;
                                }
                                if (j as usize) > i
                                    && (position[j as usize] - *p).length_squared() < cutoff2
                                {
                                    pairs.push((i as u32, j));
                                }
                            }
                        }
                    }
                }
                pairs[first..].sort_unstable();
            }
            pairs
        })
        .collect();
    lists.concat()
}
