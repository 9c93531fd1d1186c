//! Monomer–monomer force pass: inelastic corrections first (booked per channel as the drop of
//! the contact's tangential potential), then JKR, damping, rolling, sliding and twisting.

use crate::model::{rolling, sliding, twisting, ContactLaw};
use crate::state::interaction::{pair_interaction, pair_step_energy};
use crate::state::{ContactTable, Dissipation, Monomers, PairContact};
use glam::DVec3;

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

/// Zeroes the accumulators and adds every monomer–monomer contact, owners in index order.
pub fn forces(
    law: &ContactLaw,
    dt: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    tally: &mut Dissipation,
) {
    monomers.force.fill(DVec3::ZERO);
    monomers.torque.fill(DVec3::ZERO);
    monomers.damping_force.fill(DVec3::ZERO);
    for i in 0..monomers.len() {
        for slot in 0..table.pair_count[i] as usize {
            let c = &mut table.pair[i * table.pair_slots + slot];
            apply_inelastic_limits(law, monomers, dt, i, c, tally);
            let j = c.partner as usize;
            let (x1, x2) = (monomers.position[i], monomers.position[j]);
            let (v1, v2) = (monomers.velocity[i], monomers.velocity[j]);
            let (f, fd, m1, m2) = pair_interaction(law, x1, x2, v1, v2, c);
            monomers.force[i] += f;
            monomers.force[j] -= f;
            monomers.damping_force[i] += fd;
            monomers.damping_force[j] -= fd;
            monomers.torque[i] += m1;
            monomers.torque[j] += m2;
        }
    }
}
