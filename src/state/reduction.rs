//! The fixed order in which both backends sum over monomers where the sum leaves the monomer
//! loop: the per-wall force sums and the diagnostics block (tally channels and contact counts).
//!
//! The CPU engine adds wall forces and tallies as it goes (one thread, monomer order); a device
//! cannot (no float atomics), so it sums per block and then over blocks. These functions do the
//! device's additions in the device's order (the twins of `reduce_walls` in
//! shaders/passes/walls.wgsl and `reduce_diagnostics` in shaders/passes/reduce.wgsl), so a test
//! can hold the block a device reads back to the bits. The block sizes are numbers of this
//! order, not of one backend: the GPU's WGSL declares the same values (a test compares them).

use super::{ContactTable, WallContact};
use glam::DVec3;

/// Consecutive monomers whose wall-contact forces one partial sum holds.
pub const REDUCE_BLOCK: usize = 64;
/// Partial sums of the diagnostics reduction (one workgroup's invocations on a device).
pub const DIAG_THREADS: usize = 64;
/// Numbers per monomer in the per-monomer tally: the seven dissipation channels in
/// [`super::Dissipation::channels`] order, then the wall work.
pub const TALLY_STRIDE: usize = 8;

/// Total force of each of `wall_count` walls, from the force of every wall-contact slot
/// (`slot_force[i * wall_slots + s]`): sums over blocks of [`REDUCE_BLOCK`] consecutive
/// monomers ([`reduce_walls_block`]), then the blocks in order ([`reduce_walls_final_from`]).
pub fn reduce_walls(table: &ContactTable, slot_force: &[DVec3], wall_count: usize) -> Vec<DVec3> {
    let n = table.wall_count.len();
    let stride = wall_count.max(1);
    let mut partials = vec![DVec3::ZERO; n.div_ceil(REDUCE_BLOCK) * stride];
    for (block, sums) in partials.chunks_mut(stride).enumerate() {
        reduce_walls_block(table, |idx| slot_force[idx], block, sums);
    }
    reduce_walls_final_from(&partials, wall_count)
}

/// One block's sums (`reduce_walls` in shaders/passes/walls.wgsl): the wall-contact forces
/// (`slot_force(slot index)`) of monomers `block · REDUCE_BLOCK …` in index and slot order,
/// added to `sums[wall]`.
pub fn reduce_walls_block(
    table: &ContactTable,
    slot_force: impl Fn(usize) -> DVec3,
    block: usize,
    sums: &mut [DVec3],
) {
    let rows = WallRows {
        rows: &table.wall,
        counts: &table.wall_count,
        slots: table.wall_slots,
        first: 0,
    };
    reduce_walls_block_of(rows, slot_force, block, sums);
}

/// The wall-contact rows of consecutive monomers from `first`: `slots` rows each, `counts`.
#[derive(Clone, Copy)]
pub struct WallRows<'a> {
    pub rows: &'a [WallContact],
    pub counts: &'a [u32],
    pub slots: usize,
    pub first: usize,
}

/// [`reduce_walls_block`] on the rows of the monomers `rows` holds (which hold the block;
/// `slot_force` still takes the slot's index in the whole table).
pub fn reduce_walls_block_of(
    rows: WallRows,
    slot_force: impl Fn(usize) -> DVec3,
    block: usize,
    sums: &mut [DVec3],
) {
    let end = rows.first + rows.counts.len();
    for i in block * REDUCE_BLOCK..((block + 1) * REDUCE_BLOCK).min(end) {
        add_wall_slots_of(rows, &slot_force, i, sums);
    }
}

/// Monomer `i`'s share of [`reduce_walls_block_of`]: its wall-contact forces in slot order,
/// added to `sums[wall]`. Called for the block's monomers in index order, it gives the
/// block's sums (the CPU's `wall_forces` adds each monomer's as it gathers it).
#[inline]
pub fn add_wall_slots_of(
    rows: WallRows,
    slot_force: impl Fn(usize) -> DVec3,
    i: usize,
    sums: &mut [DVec3],
) {
    for slot in 0..rows.counts[i - rows.first] as usize {
        let idx = i * rows.slots + slot;
        sums[rows.rows[idx - rows.first * rows.slots].wall as usize] += slot_force(idx);
    }
}

/// The blocks' sums (`wall_count.max(1)` per block, as [`reduce_walls_block`] fills them) added
/// in block order: each wall's total (`sum_wall_blocks` in shaders/engine/wall_sums.wgsl).
pub fn reduce_walls_final_from(partials: &[DVec3], wall_count: usize) -> Vec<DVec3> {
    let stride = wall_count.max(1);
    (0..wall_count)
        .map(|w| {
            partials
                .chunks(stride)
                .fold(DVec3::ZERO, |sum, p| sum + p[w])
        })
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
