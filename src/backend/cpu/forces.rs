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
use crate::state::interaction::{
    pair_geometry, pair_interaction, pair_normal_potential, pair_step_energy_at, PairGeometry,
};
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
/// moves pointers and twist, never the monomers, so the energies share the contact's
/// [`PairGeometry`] and JKR potential, evaluated at the first correction only (most contacts of
/// a loose sample need none, and then nothing extra is evaluated), and one correction's "after"
/// is the next one's "before".
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
    let mut shared: Option<(PairGeometry, f64)> = None;
    let mut energy = |c: &PairContact| {
        let (g, u) = *shared.get_or_insert_with(|| {
            let g = pair_geometry(law, p[i], p[j], v[i], v[j]);
            (g, pair_normal_potential(law, &g))
        });
        pair_step_energy_at(law, &g, u, w[i], w[j], dt, c)
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

/// Every pair contact's corrections and forces, owner by owner in parallel, into
/// `workspace.pair_result`: one entry per contact, the owners' contacts one after another
/// (`workspace.incoming.owner_start`, which must describe the table). Returns what the
/// corrections dissipated, summed per chunk of owners and then over chunks in order.
pub fn forces_per_slot(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    workspace: &mut Workspace,
) -> Dissipation {
    let slots = table.pair_slots;
    let n = monomers.len();
    let owner_start = workspace.incoming.owner_start();
    debug_assert_eq!(owner_start.len(), n + 1, "partner index out of date");
    workspace
        .pair_result
        .resize(owner_start[n] as usize, PairResult::default());
    // Each chunk of owners writes its own contiguous stretch of results.
    let mut stretches = Vec::with_capacity(n.div_ceil(CHUNK));
    let mut rest = &mut workspace.pair_result[..];
    for first in (0..n).step_by(CHUNK) {
        let end = owner_start[(first + CHUNK).min(n)] - owner_start[first];
        let (stretch, tail) = rest.split_at_mut(end as usize);
        stretches.push(stretch);
        rest = tail;
    }
    let prefetching = worthwhile(table);
    let counts = &table.pair_count;
    let chunks: Vec<Dissipation> = table
        .pair
        .par_chunks_mut(CHUNK * slots)
        .zip(stretches.into_par_iter())
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .map(|(chunk, (rows, results))| {
            let mut tally = Dissipation::default();
            let first = chunk * CHUNK;
            let counts = &counts[first..(first + CHUNK).min(n)];
            let mut out = results.iter_mut();
            for (k, &count) in counts.iter().enumerate() {
                let i = first + k;
                if prefetching {
                    prefetch_row_ahead(rows, slots, counts, k);
                    prefetch_partners_ahead(rows, slots, counts, k, |j| {
                        prefetch_one(&monomers.position[j]);
                        prefetch_one(&monomers.velocity[j]);
                    });
                }
                for c in &mut rows[k * slots..k * slots + count as usize] {
                    apply_inelastic_limits(law, monomers, dt, i, c, &mut tally);
                    let j = c.partner as usize;
                    let (x1, x2) = (monomers.position[i], monomers.position[j]);
                    let (v1, v2) = (monomers.velocity[i], monomers.velocity[j]);
                    let (force, damping, torque_owner, torque_partner) =
                        pair_interaction(law, x1, x2, v1, v2, c);
                    *out.next().expect("a result per contact") = PairResult {
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

/// Each monomer's force, damping force and torque from the per-contact results: the contacts
/// it is the partner of (in owner and slot order), then its own. Overwrites the accumulators
/// (the walls pass adds to them).
pub fn gather_pair_forces(monomers: &mut Monomers, workspace: &Workspace) {
    let incoming = &workspace.incoming;
    let owner_start = incoming.owner_start();
    let results = &workspace.pair_result;
    each_accumulator(monomers, |i, force, damping, torque| {
        let (mut f, mut fd, mut t) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for &idx in incoming.of(i) {
            let r = &results[idx as usize];
            f -= r.force;
            fd -= r.damping;
            t += r.torque_partner;
        }
        for r in &results[owner_start[i] as usize..owner_start[i + 1] as usize] {
            f += r.force;
            fd += r.damping;
            t += r.torque_owner;
        }
        *force = f;
        *damping = fd;
        *torque = t;
    });
}

/// The pass: the partner index (after contact events), corrections and per-contact forces,
/// the gather. Adds what the
/// corrections dissipated to `tally`.
pub fn forces(
    law: &ContactLaw,
    dt: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    tally: &mut Dissipation,
    workspace: &mut Workspace,
) {
    if !workspace.partner_index_current {
        workspace.incoming.rebuild(table);
        workspace.partner_index_current = true;
    }
    let dissipated = forces_per_slot(law, dt, monomers, table, workspace);
    gather_pair_forces(monomers, workspace);
    tally.add(&dissipated);
}
