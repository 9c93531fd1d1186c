//! Leap-frog pass: kick v(n−½) → v(n+½) with the forces at n, turn contact pointers and advance
//! twist integrals with the mid-step angular velocities, drift positions and walls.

use crate::model::pointer::rotate_pointer;
use crate::model::twisting::twist_increment;
use crate::state::{ContactTable, Monomers, Wall};

/// One leap-frog step, as the device does it in three passes (the twins of the WGSL entry
/// points of the same names).
pub fn integrate(
    dt: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    walls: &mut [Wall],
) {
    integrate_kick(dt, inverse_mass, inverse_inertia, monomers, table, walls);
    integrate_pairs(dt, monomers, table);
    integrate_drift(dt, monomers, walls);
}

/// Kick, and the wall contacts' pointers and twist, which need only the monomer's own
/// mid-step spin.
pub fn integrate_kick(
    dt: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    walls: &[Wall],
) {
    for i in 0..monomers.len() {
        monomers.velocity[i] +=
            monomers.force[i] * (dt * inverse_mass * monomers.inverse_mass_scale[i]);
        monomers.angular_velocity[i] +=
            monomers.torque[i] * (dt * inverse_inertia * monomers.inverse_inertia_scale[i]);
        let omega = monomers.angular_velocity[i];
        for slot in 0..table.wall_count[i] as usize {
            let c = &mut table.wall[i * table.wall_slots + slot];
            c.twist += twist_increment(omega, walls[c.wall as usize].normal, dt);
            c.n1 = rotate_pointer(c.n1, omega * dt);
        }
    }
}

/// Both pointers and the twist integral of every pair contact, with the kicked velocities
/// and the positions before the drift.
pub fn integrate_pairs(dt: f64, monomers: &Monomers, table: &mut ContactTable) {
    let pos = &monomers.position;
    let vel = &monomers.velocity;
    let omega = &monomers.angular_velocity;
    for i in 0..monomers.len() {
        for slot in 0..table.pair_count[i] as usize {
            let c = &mut table.pair[i * table.pair_slots + slot];
            let j = c.partner as usize;
            // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
            let nc_mid = ((pos[i] - pos[j]) + (vel[i] - vel[j]) * (0.5 * dt)).normalize();
            c.twist += twist_increment(omega[i] - omega[j], nc_mid, dt);
            c.n1 = rotate_pointer(c.n1, omega[i] * dt);
            c.n2 = rotate_pointer(c.n2, omega[j] * dt);
        }
    }
}

/// Positions and walls.
pub fn integrate_drift(dt: f64, monomers: &mut Monomers, walls: &mut [Wall]) {
    for i in 0..monomers.len() {
        monomers.position[i] += monomers.velocity[i] * dt;
    }
    for w in walls.iter_mut() {
        w.point += w.velocity * dt;
    }
}
