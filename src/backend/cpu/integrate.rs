//! Leap-frog pass: kick v(n−½) → v(n+½) with the forces at n, turn contact pointers and advance
//! twist integrals with the mid-step angular velocities, drift positions and walls.
//!
//! Every loop is per monomer (or per owner row) with no sums across monomers, so it runs in
//! parallel with the same bits for any thread count.

use super::prefetch::{prefetch_one, prefetch_partners_ahead, prefetch_row_ahead, worthwhile};
use super::workspace::{split_len, CHUNK};
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
/// mid-step spin. Parallel over chunks of monomers, a plain loop within each.
pub fn integrate_kick(
    dt: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    walls: &[Wall],
) {
    let ws = table.wall_slots;
    let n = monomers.len();
    let m = monomers;
    let (force, torque) = (&m.force, &m.torque);
    let (mass_scale, inertia_scale) = (&m.inverse_mass_scale, &m.inverse_inertia_scale);
    (
        m.velocity.par_chunks_mut(CHUNK),
        m.angular_velocity.par_chunks_mut(CHUNK),
        table.wall.par_chunks_mut(CHUNK * ws),
        table.wall_count.par_chunks(CHUNK),
    )
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .for_each(|(chunk, (velocity, spin, wall_rows, counts))| {
            let first = chunk * CHUNK;
            for k in 0..velocity.len() {
                let i = first + k;
                velocity[k] += force[i] * (dt * inverse_mass * mass_scale[i]);
                spin[k] += torque[i] * (dt * inverse_inertia * inertia_scale[i]);
                let omega = spin[k];
                for c in &mut wall_rows[k * ws..k * ws + counts[k] as usize] {
                    c.twist += twist_increment(omega, walls[c.wall as usize].normal, dt);
                    c.n1 = rotate_pointer(c.n1, omega * dt);
                }
            }
        });
}

/// Both pointers and the twist integral of every pair contact, with the kicked velocities
/// and the positions before the drift. Parallel over chunks of owners.
pub fn integrate_pairs(dt: f64, monomers: &Monomers, table: &mut ContactTable) {
    let pos = &monomers.position;
    let vel = &monomers.velocity;
    let omega = &monomers.angular_velocity;
    let ps = table.pair_slots;
    let prefetching = worthwhile(table);
    (
        table.pair.par_chunks_mut(CHUNK * ps),
        table.pair_count.par_chunks(CHUNK),
    )
        .into_par_iter()
        .with_min_len(split_len(pos.len(), CHUNK))
        .enumerate()
        .for_each(|(chunk, (rows, counts))| {
            let first = chunk * CHUNK;
            for (k, &count) in counts.iter().enumerate() {
                let i = first + k;
                if prefetching {
                    prefetch_row_ahead(rows, ps, counts, k);
                    prefetch_partners_ahead(rows, ps, counts, k, |j| {
                        prefetch_one(&pos[j]);
                        prefetch_one(&vel[j]);
                        prefetch_one(&omega[j]);
                    });
                }
                for c in &mut rows[k * ps..k * ps + count as usize] {
                    let j = c.partner as usize;
                    // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
                    let nc_mid = ((pos[i] - pos[j]) + (vel[i] - vel[j]) * (0.5 * dt)).normalize();
                    c.twist += twist_increment(omega[i] - omega[j], nc_mid, dt);
                    c.n1 = rotate_pointer(c.n1, omega[i] * dt);
                    c.n2 = rotate_pointer(c.n2, omega[j] * dt);
                }
            }
        });
}

/// Positions and walls.
pub fn integrate_drift(dt: f64, monomers: &mut Monomers, walls: &mut [Wall]) {
    let velocity = &monomers.velocity;
    monomers
        .position
        .par_chunks_mut(CHUNK)
        .zip(velocity.par_chunks(CHUNK))
        .with_min_len(split_len(velocity.len(), CHUNK))
        .for_each(|(x, v)| {
            for (x, v) in x.iter_mut().zip(v) {
                *x += *v * dt;
            }
        });
    for w in walls.iter_mut() {
        w.point += w.velocity * dt;
    }
}
