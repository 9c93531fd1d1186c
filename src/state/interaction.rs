//! The contact law evaluated on a stored contact: the force and torques a pair or wall contact
//! exerts, the potential it holds, and its step energy (potential plus half the step's work),
//! which the dissipation tally books at every discontinuous change. Both backends and the
//! energy report evaluate contacts through these functions; `shaders/engine/interaction.wgsl`
//! is their WGSL twin (same names, same operations in the same order).

use super::{Monomers, PairContact, Wall, WallContact};
use crate::model::damping::damping_coefficient;
use crate::model::normal::{
    jkr_contact_radius_ratio, jkr_force, jkr_potential_at_overlap, jkr_potential_at_overlap_with,
};
use crate::model::{rolling, sliding, twisting, wall as wall_law, ContactLaw};
use glam::DVec3;

/// What a pair contact's force and energy take from the two monomers' positions and velocities
/// alone, not from its pointers or twist: evaluated once and shared by the force and the step
/// energy of a contact event (the same operations as evaluating it each time, so the same
/// bits). The inelastic corrections need only its [`PairFrame`] part.
#[derive(Clone, Copy, Debug)]
pub struct PairGeometry {
    pub distance: f64,
    /// Overlap ratio δ/δ₀ and the contact radius ratio a/a₀ it gives.
    pub overlap_ratio: f64,
    pub radius_ratio: f64,
    /// Unit vector from 2 to 1 (d / |d|).
    pub nc: DVec3,
    /// JKR force on 1.
    pub normal: DVec3,
    /// Damping force on 1.
    pub damping: DVec3,
    /// v₁ − v₂.
    pub v_rel: DVec3,
}

/// The [`PairGeometry`] of monomers at `x1`, `x2` moving at `v1`, `v2`.
pub fn pair_geometry(law: &ContactLaw, x1: DVec3, x2: DVec3, v1: DVec3, v2: DVec3) -> PairGeometry {
    let k = &law.pair;
    let r = law.radius;
    let d = x1 - x2;
    let distance = d.length();
    let nc = d / distance;
    let overlap_ratio = (2.0 * r - distance) / k.delta0;
    let x = jkr_contact_radius_ratio(overlap_ratio);
    let normal = nc * jkr_force(x, k.f_c);
    let coefficient = damping_coefficient(&law.damping, x * k.a0, law.e_star, law.poisson);
    let v_rel = v1 - v2;
    let damping = nc * (-coefficient * v_rel.dot(nc));
    PairGeometry {
        distance,
        overlap_ratio,
        radius_ratio: x,
        nc,
        normal,
        damping,
        v_rel,
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
    pair_interaction_at(law, &pair_geometry(law, x1, x2, v1, v2), c)
}

/// [`pair_interaction`] on a contact whose [`PairGeometry`] is known.
pub fn pair_interaction_at(
    law: &ContactLaw,
    g: &PairGeometry,
    c: &PairContact,
) -> (DVec3, DVec3, DVec3, DVec3) {
    let (slide, torque1, torque2) = pair_tangential(law, g.nc, g.distance, c);
    (g.normal + g.damping + slide, g.damping, torque1, torque2)
}

/// The rolling, sliding and twisting part of a contact's interaction: (sliding force on 1,
/// torque on 1, torque on 2), for unit normal `nc` at centre distance `distance`.
fn pair_tangential(
    law: &ContactLaw,
    nc: DVec3,
    distance: f64,
    c: &PairContact,
) -> (DVec3, DVec3, DVec3) {
    let k = &law.pair;
    let r = law.radius;
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
    (slide, torque1, torque2)
}

/// What the tangential part of a pair contact's step energy takes from the two monomers'
/// positions and velocities: centre distance, unit normal d / |d| and v₁ − v₂ (the operations
/// of [`pair_geometry`] for these, so the same bits).
#[derive(Clone, Copy, Debug)]
pub struct PairFrame {
    pub distance: f64,
    pub nc: DVec3,
    pub v_rel: DVec3,
}

/// The [`PairFrame`] of monomers at `x1`, `x2` moving at `v1`, `v2`.
pub fn pair_frame(x1: DVec3, x2: DVec3, v1: DVec3, v2: DVec3) -> PairFrame {
    let d = x1 - x2;
    let distance = d.length();
    PairFrame {
        distance,
        nc: d / distance,
        v_rel: v1 - v2,
    }
}

/// The part of a pair contact's step energy ([`pair_step_energy`]) that an inelastic correction
/// changes: the rolling, sliding and twisting potentials (added in that order) plus half the
/// work of their force and torques over the step, for monomers spinning at `w1`, `w2`.
///
/// A correction moves pointers and twist, never the monomers, so the JKR and damping terms of
/// the step energy are the same before and after it and its drop is this part's drop: the
/// corrections book that, without the JKR inversion and potential the whole energy needs.
pub fn pair_tangential_step_energy(
    law: &ContactLaw,
    frame: &PairFrame,
    w1: DVec3,
    w2: DVec3,
    dt: f64,
    c: &PairContact,
) -> f64 {
    let k = &law.pair;
    let (slide, torque1, torque2) = pair_tangential(law, frame.nc, frame.distance, c);
    let work = slide.dot(frame.v_rel) + torque1.dot(w1) + torque2.dot(w2);
    let xi = rolling::rolling_displacement(c.n1, c.n2, k.reduced_radius);
    let zeta = sliding::sliding_displacement(c.n1, c.n2, frame.nc, law.radius, law.radius);
    rolling::rolling_potential(xi, k.k_r)
        + sliding::sliding_potential(zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
        + 0.5 * dt * work
}

/// Potential energy held by a monomer–monomer contact (normal + tangential) [erg].
pub fn pair_contact_potential(law: &ContactLaw, x1: DVec3, x2: DVec3, c: &PairContact) -> f64 {
    let k = &law.pair;
    let d = x1 - x2;
    let distance = d.length();
    let nc = d / distance;
    let delta = 2.0 * law.radius - distance;
    let normal = jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0);
    pair_potential_with(law, normal, nc, c)
}

/// The JKR part of [`pair_contact_potential`] at a known [`PairGeometry`].
pub fn pair_normal_potential(law: &ContactLaw, g: &PairGeometry) -> f64 {
    let k = &law.pair;
    jkr_potential_at_overlap_with(g.radius_ratio, g.overlap_ratio, k.f_c, k.delta0)
}

/// The JKR potential `normal` plus the rolling, sliding and twisting potentials of a contact
/// with normal `nc`, added in that order.
fn pair_potential_with(law: &ContactLaw, normal: f64, nc: DVec3, c: &PairContact) -> f64 {
    let k = &law.pair;
    let xi = rolling::rolling_displacement(c.n1, c.n2, k.reduced_radius);
    let zeta = sliding::sliding_displacement(c.n1, c.n2, nc, law.radius, law.radius);
    normal
        + rolling::rolling_potential(xi, k.k_r)
        + sliding::sliding_potential(zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
}

/// Energy of a contact state as the leap-frog sees it: its potential plus half the work its
/// conservative forces and torques do over the step just taken (relative displacement
/// (v₁ − v₂)dt, rotations ω dt with the mid-step velocities).
///
/// Every discontinuous change of a contact is booked as the drop of this quantity: forming and
/// breaking with the whole of it, an inelastic correction with the part it changes
/// ([`pair_tangential_step_energy`]). The integrator applies a force for half a step on either side of
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
    let g = pair_geometry(law, p[i], p[j], v[i], v[j]);
    let normal_potential = pair_normal_potential(law, &g);
    pair_step_energy_at(law, &g, normal_potential, w[i], w[j], dt, c)
}

/// [`pair_step_energy`] at a known [`PairGeometry`] and JKR potential
/// ([`pair_normal_potential`]), for monomers spinning at `w1`, `w2`.
pub fn pair_step_energy_at(
    law: &ContactLaw,
    g: &PairGeometry,
    normal_potential: f64,
    w1: DVec3,
    w2: DVec3,
    dt: f64,
    c: &PairContact,
) -> f64 {
    let (f, fd, m1, m2) = pair_interaction_at(law, g, c);
    let work = (f - fd).dot(g.v_rel) + m1.dot(w1) + m2.dot(w2);
    pair_potential_with(law, normal_potential, g.nc, c) + 0.5 * dt * work
}

/// What a wall contact's force and energy take from the monomer's position and velocity
/// alone, not from its pointer, anchor or twist (its force's JKR and damping parts).
#[derive(Clone, Copy, Debug)]
pub struct WallGeometry {
    /// JKR force on the monomer.
    pub normal: DVec3,
    /// Damping force on the monomer (against the wall's velocity).
    pub damping: DVec3,
}

/// The [`WallGeometry`] of a monomer at `x` moving at `v` against `wall`.
pub fn wall_geometry(law: &ContactLaw, x: DVec3, v: DVec3, wall: &Wall) -> WallGeometry {
    let x_ratio = jkr_contact_radius_ratio(wall_overlap_ratio(law, x, wall));
    wall_geometry_at_ratio(law, x_ratio, v, wall)
}

/// A monomer at `x`'s overlap with `wall` in units of the wall's δ₀: what the JKR contact
/// radius ratio of [`wall_geometry`] is found from.
pub fn wall_overlap_ratio(law: &ContactLaw, x: DVec3, wall: &Wall) -> f64 {
    wall_law::wall_overlap(x, wall.point, wall.normal, law.radius) / wall.constants.delta0
}

/// [`wall_geometry`] with its contact radius ratio `x_ratio` known (found several contacts at
/// a time in the CPU engine's contacts pass).
pub fn wall_geometry_at_ratio(
    law: &ContactLaw,
    x_ratio: f64,
    v: DVec3,
    wall: &Wall,
) -> WallGeometry {
    let k = &wall.constants;
    let n = wall.normal;
    let normal = n * jkr_force(x_ratio, k.f_c);
    let coefficient = damping_coefficient(&law.damping, x_ratio * k.a0, law.e_star, law.poisson);
    let damping = n * (-coefficient * (v - wall.velocity).dot(n));
    WallGeometry { normal, damping }
}

/// Force on the monomer, its damping part and the torque on it.
pub fn wall_interaction(
    law: &ContactLaw,
    x: DVec3,
    v: DVec3,
    wall: &Wall,
    c: &WallContact,
) -> (DVec3, DVec3, DVec3) {
    wall_interaction_at(law, &wall_geometry(law, x, v, wall), x, wall, c)
}

/// [`wall_interaction`] of a monomer at `x` whose [`WallGeometry`] is known.
pub fn wall_interaction_at(
    law: &ContactLaw,
    g: &WallGeometry,
    x: DVec3,
    wall: &Wall,
    c: &WallContact,
) -> (DVec3, DVec3, DVec3) {
    let t = wall_tangential(law, x, wall, c);
    (g.normal + g.damping + t.slide, g.damping, t.torque)
}

/// The rolling, sliding and twisting part of a wall contact's interaction, with the
/// displacements it was made from.
struct WallTangential {
    slide: DVec3,
    torque: DVec3,
    xi: DVec3,
    zeta: DVec3,
}

fn wall_tangential(law: &ContactLaw, x: DVec3, wall: &Wall, c: &WallContact) -> WallTangential {
    let k = &wall.constants;
    let r = law.radius;
    let n = wall.normal;
    let xi = wall_law::wall_rolling_displacement(c.n1, n, r);
    let zeta = wall_law::wall_sliding_displacement(x, c.n1, r, c.anchor, n);
    let torque = rolling::rolling_torque(c.n1, xi, r, k.k_r)
        + sliding::sliding_torque(c.n1, zeta, r, k.k_s, 1.0)
        + twisting::twisting_torque(c.twist, n, k.k_t);
    WallTangential {
        slide: wall_law::wall_sliding_force(zeta, k.k_s),
        torque,
        xi,
        zeta,
    }
}

/// Wall analogue of [`pair_tangential_step_energy`]: the rolling, sliding and twisting
/// potentials (in that order) plus half the work of their force (relative to the moving wall)
/// and torque over the step, the part of the step energy a correction changes.
pub fn wall_tangential_step_energy(
    law: &ContactLaw,
    m: &WallMotion,
    wall: &Wall,
    dt: f64,
    c: &WallContact,
) -> f64 {
    let k = &wall.constants;
    let t = wall_tangential(law, m.x, wall, c);
    let work = t.slide.dot(m.v - wall.velocity) + t.torque.dot(m.w);
    rolling::rolling_potential(t.xi, k.k_r)
        + sliding::sliding_potential(t.zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
        + 0.5 * dt * work
}

/// Potential energy held by a monomer–wall contact [erg].
pub fn wall_contact_potential(radius: f64, x: DVec3, wall: &Wall, c: &WallContact) -> f64 {
    wall_potential_with(radius, wall_normal_potential(radius, x, wall), x, wall, c)
}

/// The JKR part of [`wall_contact_potential`].
pub fn wall_normal_potential(radius: f64, x: DVec3, wall: &Wall) -> f64 {
    let k = &wall.constants;
    let delta = wall_law::wall_overlap(x, wall.point, wall.normal, radius);
    jkr_potential_at_overlap(delta / k.delta0, k.f_c, k.delta0)
}

/// The JKR potential `normal` plus the rolling, sliding and twisting potentials of a wall
/// contact, added in that order.
fn wall_potential_with(radius: f64, normal: f64, x: DVec3, wall: &Wall, c: &WallContact) -> f64 {
    let k = &wall.constants;
    let xi = wall_law::wall_rolling_displacement(c.n1, wall.normal, radius);
    let zeta = wall_law::wall_sliding_displacement(x, c.n1, radius, c.anchor, wall.normal);
    normal
        + rolling::rolling_potential(xi, k.k_r)
        + sliding::sliding_potential(zeta, k.k_s)
        + twisting::twisting_potential(c.twist, k.k_t)
}

/// Wall analogue of [`pair_step_energy`]: potential plus half the step's work
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
    let g = wall_geometry(law, p[i], v[i], wall);
    let normal_potential = wall_normal_potential(law.radius, p[i], wall);
    let motion = WallMotion {
        x: p[i],
        v: v[i],
        w: w[i],
    };
    wall_step_energy_at(law, &g, normal_potential, &motion, wall, dt, c)
}

/// A monomer's position, velocity and spin, for [`wall_step_energy_at`].
#[derive(Clone, Copy, Debug)]
pub struct WallMotion {
    pub x: DVec3,
    pub v: DVec3,
    pub w: DVec3,
}

/// [`wall_step_energy`] at a known [`WallGeometry`] and JKR potential
/// ([`wall_normal_potential`]).
pub fn wall_step_energy_at(
    law: &ContactLaw,
    g: &WallGeometry,
    normal_potential: f64,
    m: &WallMotion,
    wall: &Wall,
    dt: f64,
    c: &WallContact,
) -> f64 {
    let (f, fd, torque) = wall_interaction_at(law, g, m.x, wall, c);
    let work = (f - fd).dot(m.v - wall.velocity) + torque.dot(m.w);
    wall_potential_with(law.radius, normal_potential, m.x, wall, c) + 0.5 * dt * work
}

/// Whether a pair contact needs any inelastic correction: the tests that open the corrections
/// of `rolling_correction`, `sliding_correction` and `twisting_correction`, on the contact as
/// stored (if rolling needs none, sliding is tested on the same pointers as there; if it does,
/// the contact is corrected anyway). Twin of `beyond_limits` in shaders/engine/interaction.wgsl.
#[inline]
pub fn beyond_limits(law: &ContactLaw, x1: DVec3, x2: DVec3, c: &PairContact) -> bool {
    use std::cmp::Ordering::{Equal, Less};
    let k = &law.pair;
    let r = law.radius;
    let nc = (x1 - x2).normalize();
    // `!(x <= limit)`: a NaN displacement counts as beyond, as in the WGSL.
    let beyond = |x: f64, limit: f64| !matches!(x.partial_cmp(&limit), Some(Less | Equal));
    let rolls = beyond((c.n1 + c.n2).length() * k.reduced_radius, k.xi_crit);
    let slides = beyond(
        sliding::sliding_displacement(c.n1, c.n2, nc, r, r).length(),
        k.zeta_crit,
    );
    let twists = c.twist.abs() > k.phi_crit;
    rolls || slides || twists
}

#[cfg(test)]
mod tests;
