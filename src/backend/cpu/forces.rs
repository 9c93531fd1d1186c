//! Monomer–monomer force pass: inelastic corrections first (booked per channel as the drop of
//! the contact's tangential potential), then JKR, damping, rolling, sliding and twisting.
//!
//! Data-parallel as the device does it (shaders/passes/forces.wgsl, walls.wgsl): each owner
//! evaluates its own contacts into per-slot results (`forces_per_slot`), and each monomer then
//! gathers them in a fixed order (`gather_pair_forces`: contacts it is the partner of, by owner
//! and slot, then its own slots), the order in which a single thread adding contact by contact
//! would sum them. So the forces do not depend on the thread count and equal the device's bits.

use super::prefetch::{prefetch_one, prefetch_partners_ahead, prefetch_row_ahead, worthwhile};
use super::workspace::{each_accumulator, split_len, sum_in_order, Workspace, CHUNK};
use crate::model::{rolling, sliding, twisting, ContactLaw};
use crate::state::interaction::{pair_interaction, pair_step_energy};
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
    let nc = (monomers.position[i] - monomers.position[c.partner as usize]).normalize();
    if let Some((n1, n2)) = rolling::rolling_correction(c.n1, c.n2, k.reduced_radius, k.xi_crit) {
        let before = pair_step_energy(law, monomers, dt, i, c);
        c.n1 = n1;
        c.n2 = n2;
        tally.rolling += before - pair_step_energy(law, monomers, dt, i, c);
    }
    if let Some((n1, n2)) = sliding::sliding_correction(c.n1, c.n2, nc, r, r, k.zeta_crit) {
        let before = pair_step_energy(law, monomers, dt, i, c);
        c.n1 = n1;
        c.n2 = n2;
        tally.sliding += before - pair_step_energy(law, monomers, dt, i, c);
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
        let before = pair_step_energy(law, monomers, dt, i, c);
        c.twist = twist;
        tally.twisting += before - pair_step_energy(law, monomers, dt, i, c);
    }
}

/// Every pair contact's corrections and forces, owner by owner in parallel, into
/// `workspace.pair_result` (one entry per slot). Returns what the corrections dissipated,
/// summed per chunk of owners and then over chunks in order.
pub fn forces_per_slot(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    workspace: &mut Workspace,
) -> Dissipation {
    let slots = table.pair_slots;
    let n = monomers.len();
    workspace
        .pair_result
        .resize(n * slots, PairResult::default());
    let prefetching = worthwhile(table);
    let counts = &table.pair_count;
    let chunks: Vec<Dissipation> = table
        .pair
        .par_chunks_mut(CHUNK * slots)
        .zip(workspace.pair_result.par_chunks_mut(CHUNK * slots))
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .map(|(chunk, (rows, results))| {
            let mut tally = Dissipation::default();
            let first = chunk * CHUNK;
            let counts = &counts[first..(first + CHUNK).min(n)];
            for (k, &count) in counts.iter().enumerate() {
                let i = first + k;
                if prefetching {
                    prefetch_row_ahead(rows, slots, counts, k);
                    prefetch_row_ahead(results, slots, counts, k);
                    prefetch_partners_ahead(rows, slots, counts, k, |j| {
                        prefetch_one(&monomers.position[j]);
                        prefetch_one(&monomers.velocity[j]);
                    });
                }
                let row = &mut rows[k * slots..(k + 1) * slots];
                let out = &mut results[k * slots..(k + 1) * slots];
                for (c, result) in row.iter_mut().zip(out.iter_mut()).take(count as usize) {
                    apply_inelastic_limits(law, monomers, dt, i, c, &mut tally);
                    let j = c.partner as usize;
                    let (x1, x2) = (monomers.position[i], monomers.position[j]);
                    let (v1, v2) = (monomers.velocity[i], monomers.velocity[j]);
                    let (force, damping, torque_owner, torque_partner) =
                        pair_interaction(law, x1, x2, v1, v2, c);
                    *result = PairResult {
                        force,
                        damping,
                        torque_owner,
                        torque_partner,
                    };
                }
            }
            tally
        })
        .collect();
    sum_in_order(&chunks)
}

/// Each monomer's force, damping force and torque from the per-slot results: the contacts it
/// is the partner of (in owner and slot order), then its own slots. Overwrites the
/// accumulators (the walls pass adds to them).
pub fn gather_pair_forces(monomers: &mut Monomers, table: &ContactTable, workspace: &Workspace) {
    let slots = table.pair_slots;
    let incoming = &workspace.incoming;
    let results = &workspace.pair_result;
    let counts = &table.pair_count;
    each_accumulator(monomers, |i, force, damping, torque| {
        let (mut f, mut fd, mut t) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for &idx in incoming.of(i) {
            let r = &results[idx as usize];
            f -= r.force;
            fd -= r.damping;
            t += r.torque_partner;
        }
        for r in &results[i * slots..i * slots + counts[i] as usize] {
            f += r.force;
            fd += r.damping;
            t += r.torque_owner;
        }
        *force = f;
        *damping = fd;
        *torque = t;
    });
}

/// The pass: corrections and per-slot forces, the partner index, the gather. Adds what the
/// corrections dissipated to `tally`.
pub fn forces(
    law: &ContactLaw,
    dt: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    tally: &mut Dissipation,
    workspace: &mut Workspace,
) {
    let dissipated = forces_per_slot(law, dt, monomers, table, workspace);
    if !workspace.partner_index_current {
        workspace.incoming.rebuild(table);
        workspace.partner_index_current = true;
    }
    gather_pair_forces(monomers, table, workspace);
    tally.add(&dissipated);
}
