//! Leap-frog pass: kick v(n−½) → v(n+½) with the forces at n, turn contact pointers and advance
//! twist integrals with the mid-step angular velocities, drift positions and walls.

use super::state::{ContactTable, Monomers, Wall};
use crate::model::pointer::rotate_pointer;
use crate::model::twisting::twist_increment;

pub fn integrate(
    dt: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    walls: &mut [Wall],
) {
    let n = monomers.len();
    for i in 0..n {
        monomers.velocity[i] +=
            monomers.force[i] * (dt * inverse_mass * monomers.inverse_mass_scale[i]);
        monomers.angular_velocity[i] +=
            monomers.torque[i] * (dt * inverse_inertia * monomers.inverse_inertia_scale[i]);
    }
    let pos = &monomers.position;
    let vel = &monomers.velocity;
    let omega = &monomers.angular_velocity;
    for i in 0..n {
        for slot in 0..table.pair_count[i] as usize {
            let c = &mut table.pair[i * table.pair_slots + slot];
            let j = c.partner as usize;
            // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
            let nc_mid = ((pos[i] - pos[j]) + (vel[i] - vel[j]) * (0.5 * dt)).normalize();
            c.twist += twist_increment(omega[i] - omega[j], nc_mid, dt);
            c.n1 = rotate_pointer(c.n1, omega[i] * dt);
            c.n2 = rotate_pointer(c.n2, omega[j] * dt);
        }
        for slot in 0..table.wall_count[i] as usize {
            let c = &mut table.wall[i * table.wall_slots + slot];
            c.twist += twist_increment(omega[i], walls[c.wall as usize].normal, dt);
            c.n1 = rotate_pointer(c.n1, omega[i] * dt);
        }
    }
    for i in 0..n {
        monomers.position[i] += monomers.velocity[i] * dt;
    }
    for w in walls.iter_mut() {
        w.point += w.velocity * dt;
    }
}
