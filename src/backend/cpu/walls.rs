//! Monomer–wall force pass (Sect. 2.2): JKR with R = r, damping against the wall velocity,
//! rolling, sliding about the anchor and twisting; sums the force each wall exerts.

use super::contacts::wall_contact_potential;
use crate::state::{ContactTable, Dissipation, Monomers, Wall, WallContact};
use crate::model::damping::damping_coefficient;
use crate::model::normal::{jkr_contact_radius_ratio, jkr_force};
use crate::model::{rolling, sliding, twisting, wall as wall_law, ContactLaw};
use glam::DVec3;

/// Wall analogue of [`super::forces::pair_step_energy`]: potential plus half the step's work
/// of the contact's conservative force (relative to the moving wall) and torque.
pub fn wall_step_energy(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    wall: &Wall,
    c: &WallContact,
) -> f64 {
    let (p, v, w) = (
        &monomers.position,
        &monomers.velocity,
        &monomers.angular_velocity,
    );
    let (f, fd, m) = wall_interaction(law, p[i], v[i], wall, c);
    let work = (f - fd).dot(v[i] - wall.velocity) + m.dot(w[i]);
    wall_contact_potential(law.radius, p[i], wall, c) + 0.5 * dt * work
}

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

/// Force on the monomer, its damping part and the torque on it.
pub fn wall_interaction(
    law: &ContactLaw,
    x: DVec3,
    v: DVec3,
    wall: &Wall,
    c: &WallContact,
) -> (DVec3, DVec3, DVec3) {
    let k = &wall.constants;
    let r = law.radius;
    let n = wall.normal;
    let x_ratio = jkr_contact_radius_ratio(wall_law::wall_overlap(x, wall.point, n, r) / k.delta0);
    let normal = n * jkr_force(x_ratio, k.f_c);
    let coefficient = damping_coefficient(&law.damping, x_ratio * k.a0, law.e_star, law.poisson);
    let damping = n * (-coefficient * (v - wall.velocity).dot(n));
    let xi = wall_law::wall_rolling_displacement(c.n1, n, r);
    let zeta = wall_law::wall_sliding_displacement(x, c.n1, r, c.anchor, n);
    let torque = rolling::rolling_torque(c.n1, xi, r, k.k_r)
        + sliding::sliding_torque(c.n1, zeta, r, k.k_s, 1.0)
        + twisting::twisting_torque(c.twist, n, k.k_t);
    (
        normal + damping + wall_law::wall_sliding_force(zeta, k.k_s),
        damping,
        torque,
    )
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
