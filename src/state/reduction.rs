//! Twin of shaders/reduce.wgsl: the fixed-order sums behind the GPU's diagnostics block.
//!
//! The CPU engine adds wall forces and tallies as it goes (one thread, monomer order); the
//! device cannot (no float atomics), so it sums per block and then over blocks. These functions
//! do the device's additions in the device's order, so a test can hold the block it reads back
//! to the bits.

use crate::state::ContactTable;
use crate::backend::gpu::layout::{DIAG_THREADS, REDUCE_BLOCK, TALLY_STRIDE};
use glam::DVec3;

/// Total force of each of `wall_count` walls, from the force of every wall-contact slot
/// (`slot_force[i * wall_slots + s]`): sums over blocks of [`REDUCE_BLOCK`] consecutive
/// monomers (`reduce_walls`), then the blocks in order (`reduce_walls_final`).
pub fn reduce_walls(table: &ContactTable, slot_force: &[DVec3], wall_count: usize) -> Vec<DVec3> {
    let n = table.wall_count.len();
    let partials: Vec<Vec<DVec3>> = (0..n.div_ceil(REDUCE_BLOCK))
        .map(|block| {
            let mut sums = vec![DVec3::ZERO; wall_count];
            for i in block * REDUCE_BLOCK..((block + 1) * REDUCE_BLOCK).min(n) {
                for slot in 0..table.wall_count[i] as usize {
                    let idx = i * table.wall_slots + slot;
                    sums[table.wall[idx].wall as usize] += slot_force[idx];
                }
            }
            sums
        })
        .collect();
    (0..wall_count)
        .map(|w| partials.iter().fold(DVec3::ZERO, |sum, p| sum + p[w]))
        .collect()
}

/// What `reduce_diagnostics` writes: the tally channels summed over monomers, and the pair and
/// wall contact counts.
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedDiagnostics {
    pub tally: [f64; TALLY_STRIDE],
    pub pair_contacts: usize,
    pub wall_contacts: usize,
}

/// Per-monomer tallies and contact counts reduced as one workgroup of [`DIAG_THREADS`] does:
/// invocation t sums monomers t, t + DIAG_THREADS, …; then the partial sums are added in
/// invocation order.
pub fn reduce_diagnostics(
    tally: &[[f64; TALLY_STRIDE]],
    table: &ContactTable,
) -> ReducedDiagnostics {
    let n = tally.len();
    let mut total = [0.0; TALLY_STRIDE];
    let (mut pairs, mut walls) = (0, 0);
    for t in 0..DIAG_THREADS {
        let mut sums = [0.0; TALLY_STRIDE];
        for i in (t..n).step_by(DIAG_THREADS) {
            for (s, v) in sums.iter_mut().zip(&tally[i]) {
                *s += v;
            }
            pairs += table.pair_count[i] as usize;
            walls += table.wall_count[i] as usize;
        }
        for (c, s) in total.iter_mut().zip(sums) {
            *c += s;
        }
    }
    ReducedDiagnostics {
        tally: total,
        pair_contacts: pairs,
        wall_contacts: walls,
    }
}
