//! Monomer–wall force pass (Sect. 2.2): JKR with R = r, damping against the wall velocity,
//! rolling, sliding about the anchor and twisting; sums the force each wall exerts.

use crate::model::{twisting, wall as wall_law, ContactLaw};
use crate::state::interaction::{wall_interaction, wall_step_energy};
use crate::state::{ContactTable, Dissipation, Monomers, Wall, WallContact};
use glam::DVec3;

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
    let k = &wall.constants;
    let radius = law.radius;
    let x = monomers.position[i];
    let before = wall_step_energy(law, monomers, dt, i, wall, c);
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
        tally.walls += before - wall_step_energy(law, monomers, dt, i, wall, c);
    }
}

/// Adds wall contacts to the accumulators; fills `wall_force` and `wall_damping` with the total
/// force (and its damping part) each wall exerts on the monomers.
pub fn wall_forces(
    law: &ContactLaw,
    dt: f64,
    walls: &[Wall],
    monomers: &mut Monomers,
    table: &mut ContactTable,
    tally: &mut Dissipation,
    wall_force: &mut [DVec3],
    wall_damping: &mut [DVec3],
) {
    wall_force.fill(DVec3::ZERO);
    wall_damping.fill(DVec3::ZERO);
    for i in 0..monomers.len() {
        for slot in 0..table.wall_count[i] as usize {
            let c = &mut table.wall[i * table.wall_slots + slot];
            let w = c.wall as usize;
            let x = monomers.position[i];
            apply_wall_inelastic_limits(law, monomers, dt, i, &walls[w], c, tally);
            let (f, fd, m) = wall_interaction(law, x, monomers.velocity[i], &walls[w], c);
            monomers.force[i] += f;
            monomers.damping_force[i] += fd;
            monomers.torque[i] += m;
            wall_force[w] += f;
            wall_damping[w] += fd;
        }
    }
}
