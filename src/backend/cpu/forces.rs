//! Monomer–monomer contacts: the inelastic corrections (booked per channel as the drop of the
//! contact's step energy; the contacts pass applies them as the device does, the CPU step in
//! `integrate_pairs_step`, `forces_corrections` alone in tests) and the force pass, JKR,
//! damping, rolling, sliding and twisting: the twins of `forces_corrections` and `forces` in
//! shaders/passes/forces.wgsl. The CPU step evaluates the forces in `integrate_pairs_step` too,
//! and its `forces` only those of the rows the contact events changed
//! ([`forces_of_changed_rows`]).
//!
//! Data-parallel as the device does it: each owner evaluates its own contacts into per-contact
//! results, and `wall_forces` (walls.rs) gathers them per monomer in a fixed order (contacts it
//! is the partner of, by owner and slot, then its own slots), the order in which a single
//! thread adding contact by contact would sum them. So the forces do not depend on the thread
//! count and equal the device's bits.

use super::forces_lanes::{chunk_forces, scalar_result, ContactLanes, OwnerChunk, ResultPlaces};
use super::prefetch::for_contact_passes;
use super::workspace::{split_at_offsets, split_len, Workspace, CHUNK};
use crate::backend::script::{OWNER_CORRECTIONS, OWNER_INDEX};
use crate::model::{rolling, sliding, twisting, ContactLaw};
use crate::state::interaction::{pair_frame, pair_tangential_step_energy, PairFrame};
use crate::state::{ContactTable, Dissipation, Monomers, PairContact};
use glam::DVec3;
use rayon::prelude::*;

/// What one pair contact exerts: the force on its owner, the damping part of it, and the
/// torques on owner and partner.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairResult {
    pub force: DVec3,
    pub damping: DVec3,
    pub torque_owner: DVec3,
    pub torque_partner: DVec3,
}

/// Applies the inelastic limits to one contact in the order rolling, sliding, twisting.
///
/// Each correction books its dissipation as the drop of the contact's step energy. A correction
/// moves pointers and twist, never the monomers, so only the tangential part of that energy
/// changes ([`pair_tangential_step_energy`]); its states share the contact's [`PairFrame`],
/// made at the first correction only (most contacts of a loose sample need none, and then
/// nothing extra is evaluated), and one correction's "after" is the next one's "before".
pub fn apply_inelastic_limits(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    c: &mut PairContact,
    tally: &mut Dissipation,
) {
    let k = &law.pair;
    let r = law.radius;
    let j = c.partner as usize;
    let (p, v, w) = (
        &monomers.position,
        &monomers.velocity,
        &monomers.angular_velocity,
    );
    let nc = (p[i] - p[j]).normalize();
    let mut frame: Option<PairFrame> = None;
    let mut energy = |c: &PairContact| {
        let f = *frame.get_or_insert_with(|| pair_frame(p[i], p[j], v[i], v[j]));
        pair_tangential_step_energy(law, &f, w[i], w[j], dt, c)
    };
    // The step energy of the contact as it stands.
    let mut current = None;
    if let Some((n1, n2)) = rolling::rolling_correction(c.n1, c.n2, k.reduced_radius, k.xi_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.n1 = n1;
        c.n2 = n2;
        let after = energy(c);
        tally.rolling += before - after;
        current = Some(after);
    }
    if let Some((n1, n2)) = sliding::sliding_correction(c.n1, c.n2, nc, r, r, k.zeta_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.n1 = n1;
        c.n2 = n2;
        let after = energy(c);
        tally.sliding += before - after;
        current = Some(after);
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.twist = twist;
        tally.twisting += before - energy(c);
    }
}

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
