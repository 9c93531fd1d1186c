//! Monomer–wall force pass (Sect. 2.2): JKR with R = r, damping against the wall velocity,
//! rolling, sliding about the anchor and twisting; sums the force each wall exerts.
//!
//! As on the device: each monomer evaluates its wall contacts into per-slot results, adds them
//! to its accumulators in slot order, and the per-wall totals are summed in the fixed block
//! order of [`reduce_walls`] (the twin of the device's reduction), so they do not depend on the
//! thread count and equal the device's bits.

use super::workspace::{each_accumulator, split_len, sum_in_order, Workspace, CHUNK};
use crate::model::{twisting, wall as wall_law, ContactLaw};
use crate::state::interaction::{
    wall_geometry, wall_interaction_at, wall_normal_potential, wall_step_energy_at, WallGeometry,
    WallMotion,
};
use crate::state::reduction::reduce_walls;
use crate::state::{ContactTable, Dissipation, Monomers, Wall, WallContact};
use glam::DVec3;
use rayon::prelude::*;

/// Inelastic limits of a wall contact; everything dissipated goes to the `walls` channel.
pub fn apply_wall_inelastic_limits(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    wall: &Wall,
    c: &mut WallContact,
    tally: &mut Dissipation,
) {
    let g = wall_geometry(law, monomers.position[i], monomers.velocity[i], wall);
    apply_wall_inelastic_limits_at(law, monomers, &g, dt, i, wall, c, tally);
}

/// [`apply_wall_inelastic_limits`] on a contact whose [`WallGeometry`] is known: the step
/// energies before and after share it (a correction moves pointer, anchor and twist, never the
/// monomer), and they are evaluated only where a correction changed the contact.
#[allow(clippy::too_many_arguments)]
pub fn apply_wall_inelastic_limits_at(
    law: &ContactLaw,
    monomers: &Monomers,
    g: &WallGeometry,
    dt: f64,
    i: usize,
    wall: &Wall,
    c: &mut WallContact,
    tally: &mut Dissipation,
) {
    let k = &wall.constants;
    let radius = law.radius;
    let x = monomers.position[i];
    let original = *c;
    let mut changed = false;
    if let Some((n1, anchor)) =
        wall_law::wall_rolling_correction(c.n1, c.anchor, wall.normal, radius, k.xi_crit)
    {
        c.n1 = n1;
        c.anchor = anchor;
        changed = true;
    }
    let zeta = wall_law::wall_sliding_displacement(x, c.n1, radius, c.anchor, wall.normal);
    if let Some(anchor) = wall_law::wall_sliding_correction(c.anchor, zeta, k.zeta_crit) {
        c.anchor = anchor;
        changed = true;
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
        c.twist = twist;
        changed = true;
    }
    if changed {
        let motion = WallMotion {
            x,
            v: monomers.velocity[i],
            w: monomers.angular_velocity[i],
        };
        let u = wall_normal_potential(radius, x, wall);
        let before = wall_step_energy_at(law, g, u, &motion, wall, dt, &original);
        tally.walls += before - wall_step_energy_at(law, g, u, &motion, wall, dt, c);
    }
}

/// Every wall contact's corrections and force, monomer by monomer in parallel, into the
/// workspace's per-slot results. Returns what the corrections dissipated.
pub fn wall_forces_per_slot(
    law: &ContactLaw,
    dt: f64,
    walls: &[Wall],
    monomers: &Monomers,
    table: &mut ContactTable,
    workspace: &mut Workspace,
) -> Dissipation {
    let slots = table.wall_slots;
    let len = monomers.len() * slots;
    // Slots beyond a monomer's count are never read, so stale values there are harmless.
    for v in [
        &mut workspace.wall_force,
        &mut workspace.wall_damping,
        &mut workspace.wall_torque,
    ] {
        v.resize(len, DVec3::ZERO);
    }
    let counts = &table.wall_count;
    let chunks: Vec<Dissipation> = (
        table.wall.par_chunks_mut(CHUNK * slots),
        workspace.wall_force.par_chunks_mut(CHUNK * slots),
        workspace.wall_damping.par_chunks_mut(CHUNK * slots),
        workspace.wall_torque.par_chunks_mut(CHUNK * slots),
    )
        .into_par_iter()
        .with_min_len(split_len(monomers.len(), CHUNK))
        .enumerate()
        .map(|(chunk, (rows, forces, dampings, torques))| {
            let mut tally = Dissipation::default();
            for k in 0..rows.len() / slots {
                let i = chunk * CHUNK + k;
                for s in k * slots..k * slots + counts[i] as usize {
                    let c = &mut rows[s];
                    let wall = &walls[c.wall as usize];
                    let x = monomers.position[i];
                    let g = wall_geometry(law, x, monomers.velocity[i], wall);
                    apply_wall_inelastic_limits_at(law, monomers, &g, dt, i, wall, c, &mut tally);
                    let (f, fd, m) = wall_interaction_at(law, &g, x, wall, c);
                    forces[s] = f;
                    dampings[s] = fd;
                    torques[s] = m;
                }
            }
            tally
        })
        .collect();
    sum_in_order(&chunks)
}

/// Adds wall contacts to the accumulators; fills `wall_force` and `wall_damping` with the total
/// force (and its damping part) each wall exerts on the monomers.
#[allow(clippy::too_many_arguments)]
pub fn wall_forces(
    law: &ContactLaw,
    dt: f64,
    walls: &[Wall],
    monomers: &mut Monomers,
    table: &mut ContactTable,
    tally: &mut Dissipation,
    wall_force: &mut [DVec3],
    wall_damping: &mut [DVec3],
    workspace: &mut Workspace,
) {
    let dissipated = wall_forces_per_slot(law, dt, walls, monomers, table, workspace);
    let slots = table.wall_slots;
    let counts = &table.wall_count;
    let ws = &*workspace;
    each_accumulator(monomers, |i, force, damping, torque| {
        for s in i * slots..i * slots + counts[i] as usize {
            *force += ws.wall_force[s];
            *damping += ws.wall_damping[s];
            *torque += ws.wall_torque[s];
        }
    });
    wall_force.copy_from_slice(&reduce_walls(table, &ws.wall_force, walls.len()));
    wall_damping.copy_from_slice(&reduce_walls(table, &ws.wall_damping, walls.len()));
    tally.add(&dissipated);
}
