//! Monomer–wall contacts, one contact at a time (Sect. 2.2: JKR with R = r, damping against
//! the wall velocity, rolling, sliding about the anchor and twisting): the inelastic limits
//! and the forces of one monomer's wall contacts, the twins of `wall_contacts_of` in
//! shaders/engine/owner.wgsl. The passes run them (passes/contacts.rs, passes/walls.rs).

use super::results::WallResult;
use crate::model::{twisting, wall as wall_law, ContactLaw};
use crate::state::interaction::{
    wall_geometry, wall_geometry_at_ratio, wall_interaction_at, wall_tangential_step_energy,
    WallMotion,
};
use crate::state::{Dissipation, Monomers, Wall, WallContact};

/// Inelastic limits of a wall contact (everything dissipated goes to the `walls` channel),
/// booked as the drop of the contact's tangential step energy
/// ([`wall_tangential_step_energy`]: a correction moves pointer, anchor and twist, never the
/// monomer, so nothing else changes), evaluated only where a correction changed the contact
/// and there is a tally (the channel booked).
pub fn apply_wall_inelastic_limits(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    wall: &Wall,
    c: &mut WallContact,
    tally: Option<&mut Dissipation>,
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
    if let Some(tally) = tally.filter(|_| changed) {
        let motion = WallMotion {
            x,
            v: monomers.velocity[i],
            w: monomers.angular_velocity[i],
        };
        let before = wall_tangential_step_energy(law, &motion, wall, dt, &original);
        tally.walls += before - wall_tangential_step_energy(law, &motion, wall, dt, c);
    }
}

/// The wall contacts of monomer `i` (`rows`, its contacts in slot order): inelastic limits,
/// then forces into `results` (one per slot), the limits' dissipation into `tally` where
/// there is one. `known` may hold per slot a wall and the contact radius ratio against it,
/// found beforehand (the contacts pass finds them four at a time); a slot whose contact is
/// against another wall finds its own. Twin of `wall_contacts_of` in
/// shaders/engine/owner.wgsl.
#[allow(clippy::too_many_arguments)]
pub fn wall_contacts_of(
    law: &ContactLaw,
    dt: f64,
    walls: &[Wall],
    monomers: &Monomers,
    i: usize,
    rows: &mut [WallContact],
    (results, known): (&mut [WallResult], &[(u32, f64)]),
    mut tally: Option<&mut Dissipation>,
) {
    let (x, v) = (monomers.position[i], monomers.velocity[i]);
    for (s, (c, out)) in rows.iter_mut().zip(results).enumerate() {
        let wall = &walls[c.wall as usize];
        let booked = tally.as_deref_mut();
        apply_wall_inelastic_limits(law, monomers, dt, i, wall, c, booked);
        let g = match known.get(s) {
            Some(&(w, x_ratio)) if w == c.wall => wall_geometry_at_ratio(law, x_ratio, v, wall),
            _ => wall_geometry(law, x, v, wall),
        };
        let (force, damping, torque) = wall_interaction_at(law, &g, x, wall, c);
        *out = WallResult {
            force,
            damping,
            torque,
        };
    }
}
