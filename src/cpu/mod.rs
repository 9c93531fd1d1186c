//! CPU reference backend (f64): the same passes, in the same order, as the GPU step script.
//!
//! One step: `integrate` (kick, pointers, twist, drift) → `neighbours` (refresh when stale) →
//! `contacts` (break, form) → `forces` (monomer pairs) → `walls` → work bookkeeping.

pub mod contacts;
pub mod forces;
pub mod integrate;
pub mod neighbours;
pub mod state;
pub mod walls;

use crate::model::ContactLaw;
use glam::DVec3;
use neighbours::NeighbourList;
use state::{ContactTable, Dissipation, Monomers, Wall};
use std::fmt;

/// Contact slots per monomer for partners of higher index (equal spheres touch at most 12).
pub const DEFAULT_PAIR_SLOTS: usize = 12;
/// Wall contact slots per monomer (a box corner touches 3 walls).
pub const DEFAULT_WALL_SLOTS: usize = 3;

#[derive(Clone, Debug, PartialEq)]
pub enum EngineError {
    SlotOverflow {
        kind: &'static str,
        monomer: usize,
        limit: usize,
    },
    NonFinite {
        step: u64,
        monomer: usize,
    },
}

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EngineError::SlotOverflow {
                kind,
                monomer,
                limit,
            } => write!(
                f,
                "monomer {monomer} needs more than {limit} {kind} contact slots; raise \
                 [integration] {} in the config",
                if *kind == "monomer-wall" {
                    "wall_slots"
                } else {
                    "pair_slots"
                }
            ),
            EngineError::NonFinite { step, monomer } => write!(
                f,
                "non-finite position or velocity of monomer {monomer} at step {step} \
                 (time step too large or overlapping monomers?)"
            ),
        }
    }
}

impl std::error::Error for EngineError {}

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

/// The whole simulation state of the CPU backend.
#[derive(Clone, Debug)]
pub struct CpuEngine {
    pub law: ContactLaw,
    pub dt: f64,
    pub monomers: Monomers,
    pub contacts: ContactTable,
    pub walls: Vec<Wall>,
    pub neighbours: NeighbourList,
    pub tally: Dissipation,
    pub wall_work: f64,
    /// Total force each wall exerts on the monomers, at the current time.
    pub wall_force: Vec<DVec3>,
    wall_damping: Vec<DVec3>,
    pub step: u64,
    pub time: f64,
    /// Wall-clock seconds spent in each pass, in [`PASS_NAMES`] order.
    pub pass_seconds: [f64; 5],
}

/// The passes of one step, in order.
pub const PASS_NAMES: [&str; 5] = ["integrate", "neighbours", "contacts", "forces", "walls"];

impl CpuEngine {
    /// Builds the engine with synchronised initial velocities `monomers.velocity` (time 0):
    /// finds the initial contacts, computes the forces at time 0 and shifts the velocities back
    /// half a step, as the leap-frog stores them.
    pub fn new(
        law: ContactLaw,
        dt: f64,
        monomers: Monomers,
        walls: Vec<Wall>,
        pair_slots: usize,
        wall_slots: usize,
    ) -> Result<Self, EngineError> {
        let n = monomers.len();
        let nw = walls.len();
        let mut engine = CpuEngine {
            law,
            dt,
            contacts: ContactTable::new(n, pair_slots, wall_slots),
            neighbours: NeighbourList::new(2.0 * law.radius, 0.2 * law.radius),
            monomers,
            walls,
            tally: Dissipation::default(),
            wall_work: 0.0,
            wall_force: vec![DVec3::ZERO; nw],
            wall_damping: vec![DVec3::ZERO; nw],
            step: 0,
            time: 0.0,
            pass_seconds: [0.0; 5],
        };
        engine.neighbours.refresh(&engine.monomers.position);
        contacts::update_contacts(
            &engine.law,
            dt,
            &engine.monomers,
            &engine.walls,
            &engine.neighbours.pairs,
            &mut engine.contacts,
            &mut engine.tally,
        )?;
        // Contacts present at the start are part of the initial state, not a dissipation.
        engine.tally = Dissipation::default();
        engine.compute_forces();
        let half = 0.5 * dt;
        let (im, ii) = engine.inverse_mass_inertia();
        for i in 0..n {
            let m = &mut engine.monomers;
            m.velocity[i] -= m.force[i] * (half * im * m.inverse_mass_scale[i]);
            m.angular_velocity[i] -= m.torque[i] * (half * ii * m.inverse_inertia_scale[i]);
        }
        Ok(engine)
    }

    fn inverse_mass_inertia(&self) -> (f64, f64) {
        (1.0 / self.law.mass, 1.0 / self.law.moment_of_inertia)
    }

    fn compute_forces(&mut self) {
        let clock = std::time::Instant::now();
        forces::pair_forces(
            &self.law,
            self.dt,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.tally,
        );
        self.pass_seconds[3] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        walls::wall_forces(
            &self.law,
            self.dt,
            &self.walls,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.tally,
            &mut self.wall_force,
            &mut self.wall_damping,
        );
        self.pass_seconds[4] += clock.elapsed().as_secs_f64();
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<(), EngineError> {
        let (im, ii) = self.inverse_mass_inertia();
        let clock = std::time::Instant::now();
        integrate::integrate(
            self.dt,
            im,
            ii,
            &mut self.monomers,
            &mut self.contacts,
            &mut self.walls,
        );
        self.pass_seconds[0] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        self.neighbours.refresh(&self.monomers.position);
        self.pass_seconds[1] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        contacts::update_contacts(
            &self.law,
            self.dt,
            &self.monomers,
            &self.walls,
            &self.neighbours.pairs,
            &mut self.contacts,
            &mut self.tally,
        )?;
        self.pass_seconds[2] += clock.elapsed().as_secs_f64();
        let damping_before = self.monomers.damping_force.clone();
        let wall_force_before = self.wall_force.clone();
        let wall_damping_before = self.wall_damping.clone();
        self.compute_forces();
        // Work over the step by the trapezoid rule, which matches the leap-frog's kinetic
        // energy change exactly up to a bounded, telescoping term.
        let dt = self.dt;
        let m = &self.monomers;
        let mut damping_work = 0.0;
        for i in 0..m.len() {
            damping_work += 0.5 * (damping_before[i] + m.damping_force[i]).dot(m.velocity[i] * dt);
        }
        for (w, wall) in self.walls.iter().enumerate() {
            let travel = wall.velocity * dt;
            damping_work -= 0.5 * (wall_damping_before[w] + self.wall_damping[w]).dot(travel);
            self.wall_work += 0.5 * (wall_force_before[w] + self.wall_force[w]).dot(travel);
        }
        self.tally.damping -= damping_work;
        self.step += 1;
        self.time += dt;
        if self.step.is_multiple_of(64) {
            self.check_finite()?;
        }
        Ok(())
    }

    pub fn run(&mut self, steps: u64) -> Result<(), EngineError> {
        for _ in 0..steps {
            self.step()?;
        }
        Ok(())
    }

    pub fn check_finite(&self) -> Result<(), EngineError> {
        let m = &self.monomers;
        for i in 0..m.len() {
            if !(m.position[i].is_finite() && m.velocity[i].is_finite()) {
                return Err(EngineError::NonFinite {
                    step: self.step,
                    monomer: i,
                });
            }
        }
        Ok(())
    }

    /// Velocity of monomer i at the current time (the stored one is half a step behind).
    pub fn synchronized_velocity(&self, i: usize) -> DVec3 {
        let m = &self.monomers;
        m.velocity[i] + m.force[i] * (0.5 * self.dt / self.law.mass * m.inverse_mass_scale[i])
    }

    pub fn synchronized_angular_velocity(&self, i: usize) -> DVec3 {
        let m = &self.monomers;
        m.angular_velocity[i]
            + m.torque[i]
                * (0.5 * self.dt / self.law.moment_of_inertia * m.inverse_inertia_scale[i])
    }

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
                let total =
                    contacts::pair_contact_potential(&self.law, m.position[i], m.position[j], c);
                let d = m.position[i] - m.position[j];
                let normal = crate::model::normal::jkr_potential_at_overlap(
                    (2.0 * self.law.radius - d.length()) / k.delta0,
                    k.f_c,
                    k.delta0,
                );
                e.normal_potential += normal;
                e.tangential_potential += total - normal;
            }
            for c in self.contacts.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let total = contacts::wall_contact_potential(self.law.radius, m.position[i], w, c);
                let delta = crate::model::wall::wall_overlap(
                    m.position[i],
                    w.point,
                    w.normal,
                    self.law.radius,
                );
                let normal = crate::model::normal::jkr_potential_at_overlap(
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
