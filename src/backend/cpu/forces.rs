//! Monomer–monomer force pass: inelastic corrections first (booked per channel as the drop of
//! the contact's tangential potential), then JKR, damping, rolling, sliding and twisting.

use super::contacts::pair_contact_potential;
use crate::state::{ContactTable, Dissipation, Monomers, PairContact};
use crate::model::damping::damping_coefficient;
use crate::model::normal::{jkr_contact_radius_ratio, jkr_force};
use crate::model::{rolling, sliding, twisting, ContactLaw};
use glam::DVec3;

/// Energy of a contact state as the leap-frog sees it: its potential plus half the work its
/// conservative forces and torques do over the step just taken (relative displacement
/// (v₁ − v₂)dt, rotations ω dt with the mid-step velocities).
///
/// Every discontinuous change of a contact (forming, breaking, an inelastic correction) is booked
/// as the drop of this quantity. The integrator applies a force for half a step on either side of
/// the instant it is evaluated, so booking the potential alone would leave an O(F v dt) error per
/// event in the energy balance; with the half-step term the balance closes to integration error.
pub fn pair_step_energy(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    c: &PairContact,
) -> f64 {
    let j = c.partner as usize;
    let (p, v, w) = (
        &monomers.position,
        &monomers.velocity,
        &monomers.angular_velocity,
    );
    let (f, fd, m1, m2) = pair_interaction(law, p[i], p[j], v[i], v[j], c);
    let work = (f - fd).dot(v[i] - v[j]) + m1.dot(w[i]) + m2.dot(w[j]);
    pair_contact_potential(law, p[i], p[j], c) + 0.5 * dt * work
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

/// Forces and torques of one contact: (force on 1, damping part of it, torque on 1, torque on 2).
pub fn pair_interaction(
    law: &ContactLaw,
    x1: DVec3,
    x2: DVec3,
    v1: DVec3,
    v2: DVec3,
    c: &PairContact,
) -> (DVec3, DVec3, DVec3, DVec3) {
    let k = &law.pair;
    let r = law.radius;
    let d = x1 - x2;
    let distance = d.length();
    let nc = d / distance;
    let x = jkr_contact_radius_ratio((2.0 * r - distance) / k.delta0);
    let normal = nc * jkr_force(x, k.f_c);
    let coefficient = damping_coefficient(&law.damping, x * k.a0, law.e_star, law.poisson);
    let damping = nc * (-coefficient * (v1 - v2).dot(nc));

    let xi = rolling::rolling_displacement(c.n1, c.n2, k.reduced_radius);
    let zeta = sliding::sliding_displacement(c.n1, c.n2, nc, r, r);
    let slide = sliding::sliding_force(zeta, c.n1, c.n2, nc, r, r, distance, k.k_s);
    let twist = twisting::twisting_torque(c.twist, nc, k.k_t);
    let torque1 = rolling::rolling_torque(c.n1, xi, k.reduced_radius, k.k_r)
        + sliding::sliding_torque(c.n1, zeta, r, k.k_s, 1.0)
        + twist;
    let torque2 = rolling::rolling_torque(c.n2, xi, k.reduced_radius, k.k_r)
        + sliding::sliding_torque(c.n2, zeta, r, k.k_s, -1.0)
        - twist;
    (normal + damping + slide, damping, torque1, torque2)
}

/// Zeroes the accumulators and adds every monomer–monomer contact, owners in index order.
pub fn pair_forces(
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
