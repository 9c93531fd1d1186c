//! The simulation state every backend, checkpoint and snapshot shares: monomers, contact table,
//! walls, dissipation tally and the clock ([`State`]), what a stored contact exerts and holds
//! (`interaction`), the energy report, the fixed reduction order both backends sum in, and the
//! state's byte codec for checkpoints.
//!
//! A backend steps a `State`; it never hands out anything but a `State` (borrowed on the CPU,
//! read back from a device), so everything downstream of the engines depends on this module
//! alone.

pub mod codec;
pub mod contacts;
pub mod energy;
pub mod interaction;
pub mod monomers;
pub mod order;
pub mod reduction;
pub mod rows;
pub mod tally;
pub mod walls;

pub use contacts::{
    ContactTable, PairContact, WallContact, DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS, MAX_PAIR_SLOTS,
};
pub use energy::EnergyReport;
pub use monomers::Monomers;
pub use tally::Dissipation;
pub use walls::Wall;

use crate::model::ContactLaw;
use glam::DVec3;

/// Everything a step reads and writes, at one instant of a run: what a checkpoint stores and a
/// snapshot shows. Velocities are the leap-frog's half-step values (see [`Monomers`]).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub law: ContactLaw,
    pub dt: f64,
    pub monomers: Monomers,
    pub contacts: ContactTable,
    pub walls: Vec<Wall>,
    /// Energy dissipated since time 0, per channel.
    pub tally: Dissipation,
    /// Work done on the monomers by moving walls since time 0.
    pub wall_work: f64,
    /// Total force each wall exerts on the monomers, at the current time.
    pub wall_force: Vec<DVec3>,
    /// The damping part of `wall_force`, kept to book its work over the next step (trapezoid
    /// rule). A device does not keep it: a state read back from one holds zeros here.
    pub wall_damping: Vec<DVec3>,
    pub step: u64,
    /// Simulated time [s], [`simulated_time`] of `step`.
    pub time: f64,
}

/// Simulated time after `step` steps of `dt` [s]. The one definition of time: every engine
/// keeps its clock with it, and every output that states a time (`time_s` in curve.csv and
/// profiles.csv, snapshots and their `.pvd` series, the run summary) takes it from here, so
/// the backends and a resumed run agree to the bit however their steps were batched.
pub fn simulated_time(step: u64, dt: f64) -> f64 {
    step as f64 * dt
}

impl State {
    /// Time 0: the monomers and walls as given, no contacts yet, nothing tallied. An engine
    /// starts from here (finds the initial contacts and forces).
    pub fn initial(
        law: ContactLaw,
        dt: f64,
        monomers: Monomers,
        walls: Vec<Wall>,
        pair_slots: usize,
        wall_slots: usize,
    ) -> Self {
        let (n, nw) = (monomers.len(), walls.len());
        State {
            law,
            dt,
            monomers,
            contacts: ContactTable::new(n, pair_slots, wall_slots),
            walls,
            tally: Dissipation::default(),
            wall_work: 0.0,
            wall_force: vec![DVec3::ZERO; nw],
            wall_damping: vec![DVec3::ZERO; nw],
            step: 0,
            time: 0.0,
        }
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
}
