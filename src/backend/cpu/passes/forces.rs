//! Monomer–monomer contacts: the inelastic corrections (booked per channel as the drop of the
//! contact's step energy; the contacts pass applies them as the device does, the CPU step in
//! `integrate_pairs_step`, `forces_corrections` alone in tests) and the force pass, JKR,
//! damping, rolling, sliding and twisting: the twins of `forces_corrections` and `forces` in
//! shaders/passes/forces.wgsl. The law of one contact is law/corrections_lanes.rs and
//! law/forces_lanes.rs; here, the passes over the contacts. The CPU step evaluates the forces in `integrate_pairs_step` too,
//! and its `forces` only those of the rows the contact events changed
//! ([`forces_of_changed_rows`]).
//!
//! Data-parallel as the device does it: each owner evaluates its own contacts into per-contact
//! results, and `wall_forces` (walls.rs) gathers them per monomer in a fixed order (contacts it
//! is the partner of, by owner and slot, then its own slots), the order in which a single
//! thread adding contact by contact would sum them. So the forces do not depend on the thread
//! count and equal the device's bits.

use super::prefetching::for_contact_passes;
use crate::backend::cpu::chunking::{split_at_offsets, split_len, CHUNK};
use crate::backend::cpu::lanes::ContactLanes;
use crate::backend::cpu::law::corrections_lanes::apply_inelastic_limits;
use crate::backend::cpu::law::forces_lanes::{chunk_forces, scalar_result};
use crate::backend::cpu::law::results::{OwnerChunk, PairResult, ResultPlaces};
use crate::backend::cpu::workspace::Workspace;
use crate::backend::script::{OWNER_CORRECTIONS, OWNER_INDEX};
use crate::model::ContactLaw;
use crate::state::{ContactTable, Dissipation, Monomers};
use rayon::prelude::*;

/// [`apply_inelastic_limits`] to every pair contact of the owners `contacts_scan` listed with
/// [`OWNER_CORRECTIONS`], without their contact events: the step applies them in the contacts
/// pass, after the events; this lets the forces be tested on a state whose events have not
/// run. Returns what the corrections dissipated.
pub fn forces_corrections(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    work: &[u32],
) -> Dissipation {
    let ps = table.pair_slots;
    let mut tally = Dissipation::default();
    for &item in work.iter().filter(|w| *w & OWNER_CORRECTIONS != 0) {
        let i = (item & OWNER_INDEX) as usize;
        for c in &mut table.pair[i * ps..i * ps + table.pair_count[i] as usize] {
            apply_inelastic_limits(law, monomers, dt, i, c, &mut tally);
        }
    }
    tally
}

/// Every pair contact's force, owner by owner in parallel, into `workspace.pair_result`: one
/// entry per contact, the owners' contacts one after another (`workspace.incoming`, the
/// partner index, rebuilt here after contact events).
pub fn forces(
    law: &ContactLaw,
    monomers: &Monomers,
    table: &ContactTable,
    workspace: &mut Workspace,
) {
    if !workspace.partner_index_current {
        workspace.incoming.rebuild(table);
        workspace.partner_index_current = true;
    }
    let slots = table.pair_slots;
    let n = monomers.len();
    let index = &workspace.incoming;
    let (owner_start, bases) = (index.owner_start(), index.chunk_bases());
    debug_assert_eq!(owner_start.len(), n + 1, "partner index out of date");
    workspace
        .pair_result
        .resize(owner_start[n] as usize, PairResult::default());
    // Each chunk of owners writes its own stretch of results.
    let offsets = bases.iter().map(|&b| b as usize);
    let stretches = split_at_offsets(&mut workspace.pair_result, offsets);
    let prefetching = for_contact_passes(table);
    let lanes = ContactLanes::chosen();
    let counts = &table.pair_count;
    table
        .pair
        .par_chunks(CHUNK * slots)
        .zip(stretches.into_par_iter())
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .for_each(|(chunk, (rows, results))| {
            let first = chunk * CHUNK;
            let owners = OwnerChunk {
                rows,
                slots,
                counts: &counts[first..(first + CHUNK).min(n)],
                first,
                prefetching,
            };
            let places = ResultPlaces {
                results,
                starts: Some(&owner_start[first..(first + CHUNK).min(n)]),
                base: bases[chunk],
            };
            chunk_forces(lanes, law, monomers, owners, places);
        });
}

/// The step's `forces` after its pairs pass evaluated every contact's force
/// (`integrate_pairs_step`) and the contacts pass moved them with the rows its events left
/// alone: the forces of the rows the events changed (`workspace.changed_rows`), one contact
/// at a time (23 of 10⁴ rows per step at φ 0.45). The same operations on the same values as
/// [`forces`].
pub fn forces_of_changed_rows(
    law: &ContactLaw,
    monomers: &Monomers,
    table: &ContactTable,
    workspace: &mut Workspace,
) {
    let owner_start = workspace.incoming.owner_start();
    for &i in &workspace.changed_rows {
        let i = i as usize;
        let at = owner_start[i] as usize;
        for (s, c) in table.pairs_of(i).iter().enumerate() {
            workspace.pair_result[at + s] = scalar_result(law, monomers, i, c);
        }
    }
}
