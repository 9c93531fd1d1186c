//! Leap-frog pass: kick v(n−½) → v(n+½) with the forces at n, turn contact pointers and advance
//! twist integrals with the mid-step angular velocities, drift positions and walls.
//!
//! Every loop is per monomer (or per owner row) with no sums across monomers, so it runs in
//! parallel with the same bits for any thread count.

use super::workspace::split_len;
use crate::model::pointer::rotate_pointer;
use crate::model::twisting::twist_increment;
use crate::state::{ContactTable, Monomers, Wall};
use rayon::prelude::*;

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
    let ws = table.wall_slots;
    let m = monomers;
    let (force, torque) = (&m.force, &m.torque);
    let (mass_scale, inertia_scale) = (&m.inverse_mass_scale, &m.inverse_inertia_scale);
    (
        m.velocity.par_iter_mut(),
        m.angular_velocity.par_iter_mut(),
        table.wall.par_chunks_mut(ws),
        table.wall_count.par_iter(),
    )
        .into_par_iter()
        .with_min_len(split_len(force.len(), 1))
        .enumerate()
        .for_each(|(i, (velocity, spin, wall_row, count))| {
            *velocity += force[i] * (dt * inverse_mass * mass_scale[i]);
            *spin += torque[i] * (dt * inverse_inertia * inertia_scale[i]);
            let omega = *spin;
            for c in &mut wall_row[..*count as usize] {
                c.twist += twist_increment(omega, walls[c.wall as usize].normal, dt);
                c.n1 = rotate_pointer(c.n1, omega * dt);
            }
        });
}

/// Both pointers and the twist integral of every pair contact, with the kicked velocities
/// and the positions before the drift.
pub fn integrate_pairs(dt: f64, monomers: &Monomers, table: &mut ContactTable) {
    let pos = &monomers.position;
    let vel = &monomers.velocity;
    let omega = &monomers.angular_velocity;
    let ps = table.pair_slots;
    (table.pair.par_chunks_mut(ps), table.pair_count.par_iter())
        .into_par_iter()
        .with_min_len(split_len(pos.len(), 1))
        .enumerate()
        .for_each(|(i, (row, count))| {
            for c in &mut row[..*count as usize] {
                let j = c.partner as usize;
                // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
                let nc_mid = ((pos[i] - pos[j]) + (vel[i] - vel[j]) * (0.5 * dt)).normalize();
                c.twist += twist_increment(omega[i] - omega[j], nc_mid, dt);
                c.n1 = rotate_pointer(c.n1, omega[i] * dt);
                c.n2 = rotate_pointer(c.n2, omega[j] * dt);
            }
        });
}

/// Positions and walls.
pub fn integrate_drift(dt: f64, monomers: &mut Monomers, walls: &mut [Wall]) {
    let velocity = &monomers.velocity;
    monomers
        .position
        .par_iter_mut()
        .zip(velocity.par_iter())
        .with_min_len(split_len(velocity.len(), 1))
        .for_each(|(x, v)| *x += *v * dt);
    for w in walls.iter_mut() {
        w.point += w.velocity * dt;
    }
}
