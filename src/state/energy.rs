//! The energy report of a state (mechanical energy at the synchronised time plus what has left
//! it) and its momenta: what every backend reports, computed from the state alone.

use super::interaction::{pair_contact_potential, wall_contact_potential};
use super::{Dissipation, State};
use crate::model::normal::jkr_potential_at_overlap;
use crate::model::wall::wall_overlap;
use glam::DVec3;

/// Mechanical energy at the current (synchronised) time, plus what has left it [erg].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyReport {
    pub kinetic: f64,
    pub rotational: f64,
    /// JKR potentials of all contacts (monomer–monomer and monomer–wall).
    pub normal_potential: f64,
    /// Rolling + sliding + twisting potentials of all contacts.
    pub tangential_potential: f64,
    pub dissipated: Dissipation,
    /// Work done on the monomers by moving walls.
    pub wall_work: f64,
}

impl EnergyReport {
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.rotational + self.normal_potential + self.tangential_potential
    }

    /// Conserved: mechanical + dissipated − wall work.
    pub fn balance(&self) -> f64 {
        self.mechanical() + self.dissipated.total() - self.wall_work
    }
}

impl State {
    pub fn energy(&self) -> EnergyReport {
        let mut e = EnergyReport {
            dissipated: self.tally,
            wall_work: self.wall_work,
            ..Default::default()
        };
        let m = &self.monomers;
        for i in 0..m.len() {
            if m.inverse_mass_scale[i] > 0.0 {
                e.kinetic += 0.5 * self.law.mass * self.synchronized_velocity(i).length_squared();
            }
            if m.inverse_inertia_scale[i] > 0.0 {
                e.rotational += 0.5
                    * self.law.moment_of_inertia
                    * self.synchronized_angular_velocity(i).length_squared();
            }
        }
        let k = &self.law.pair;
        for i in 0..m.len() {
            for c in self.contacts.pairs_of(i) {
                let j = c.partner as usize;
                let total = pair_contact_potential(&self.law, m.position[i], m.position[j], c);
                let d = m.position[i] - m.position[j];
                let normal = jkr_potential_at_overlap(
                    (2.0 * self.law.radius - d.length()) / k.delta0,
                    k.f_c,
                    k.delta0,
                );
                e.normal_potential += normal;
                e.tangential_potential += total - normal;
            }
            for c in self.contacts.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let total = wall_contact_potential(self.law.radius, m.position[i], w, c);
                let delta = wall_overlap(m.position[i], w.point, w.normal, self.law.radius);
                let normal = jkr_potential_at_overlap(
                    delta / w.constants.delta0,
                    w.constants.f_c,
                    w.constants.delta0,
                );
                e.normal_potential += normal;
                e.tangential_potential += total - normal;
            }
        }
        e
    }

    /// Total linear momentum (synchronised velocities) of the free monomers.
    pub fn momentum(&self) -> DVec3 {
        (0..self.monomers.len())
            .map(|i| self.synchronized_velocity(i) * self.law.mass)
            .sum()
    }

    /// Total angular momentum about the origin: orbital plus spin.
    pub fn angular_momentum(&self) -> DVec3 {
        (0..self.monomers.len())
            .map(|i| {
                self.monomers.position[i].cross(self.synchronized_velocity(i) * self.law.mass)
                    + self.synchronized_angular_velocity(i) * self.law.moment_of_inertia
            })
            .sum()
    }
}
