//! CPU reference backend (f64): the same passes, in the same order, as the GPU step script.
//!
//! One step: `integrate` (kick, pointers, twist, drift) → `neighbours` (refresh when stale) →
//! `contacts` (break, form) → `forces` (monomer pairs) → `walls` → work bookkeeping.
//!
//! A leaf: it steps a [`State`] under the [`Engine`] contract and uses nothing of another
//! backend.

pub mod contacts;
pub mod forces;
pub mod integrate;
pub mod neighbours;
pub mod walls;

use crate::engine::{Engine, EngineError, SKIN_RADII};
use crate::model::ContactLaw;
use crate::state::{simulated_time, Dissipation, EnergyReport, Monomers, State, Wall};
use glam::DVec3;
use neighbours::NeighbourList;
use std::borrow::Cow;
use std::ops::{Deref, DerefMut};

/// The CPU backend: the state it steps, plus its own search structure (the neighbour list) and
/// timings. It reads as its state (`engine.monomers`, `engine.step`, ...) through `Deref`.
#[derive(Clone, Debug)]
pub struct CpuEngine {
    pub state: State,
    pub neighbours: NeighbourList,
    /// Wall-clock seconds spent in each pass, in [`PASS_NAMES`] order.
    pub pass_seconds: [f64; 5],
}

impl Deref for CpuEngine {
    type Target = State;
    fn deref(&self) -> &State {
        &self.state
    }
}

impl DerefMut for CpuEngine {
    fn deref_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

/// The passes of one step, in order.
pub const PASS_NAMES: [&str; 5] = ["integrate", "neighbours", "contacts", "forces", "walls"];

fn neighbour_list(law: &ContactLaw) -> NeighbourList {
    NeighbourList::new(2.0 * law.radius, SKIN_RADII * law.radius)
}

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
        let mut engine = CpuEngine {
            state: State::initial(law, dt, monomers, walls, pair_slots, wall_slots),
            neighbours: neighbour_list(&law),
            pass_seconds: [0.0; 5],
        };
        engine.neighbours.refresh(&engine.state.monomers.position);
        let s = &mut engine.state;
        contacts::contacts(
            &s.law,
            dt,
            &s.monomers,
            &s.walls,
            &engine.neighbours.pairs,
            &mut s.contacts,
            &mut s.tally,
        )?;
        // Contacts present at the start are part of the initial state, not a dissipation.
        s.tally = Dissipation::default();
        engine.compute_forces();
        let half = 0.5 * dt;
        let (im, ii) = engine.inverse_mass_inertia();
        for i in 0..n {
            let m = &mut engine.state.monomers;
            m.velocity[i] -= m.force[i] * (half * im * m.inverse_mass_scale[i]);
            m.angular_velocity[i] -= m.torque[i] * (half * ii * m.inverse_inertia_scale[i]);
        }
        Ok(engine)
    }

    /// An engine holding exactly the given state, nothing recomputed (a checkpoint's, or one
    /// another backend computed); its neighbour list is built from the positions.
    pub fn from_state(state: State) -> Self {
        let mut neighbours = neighbour_list(&state.law);
        neighbours.refresh(&state.monomers.position);
        CpuEngine {
            state,
            neighbours,
            pass_seconds: [0.0; 5],
        }
    }

    fn inverse_mass_inertia(&self) -> (f64, f64) {
        (1.0 / self.law.mass, 1.0 / self.law.moment_of_inertia)
    }

    fn compute_forces(&mut self) {
        let s = &mut self.state;
        let clock = std::time::Instant::now();
        forces::forces(&s.law, s.dt, &mut s.monomers, &mut s.contacts, &mut s.tally);
        self.pass_seconds[3] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        walls::wall_forces(
            &s.law,
            s.dt,
            &s.walls,
            &mut s.monomers,
            &mut s.contacts,
            &mut s.tally,
            &mut s.wall_force,
            &mut s.wall_damping,
        );
        self.pass_seconds[4] += clock.elapsed().as_secs_f64();
    }

    /// Advances one time step.
    pub fn step(&mut self) -> Result<(), EngineError> {
        let (im, ii) = self.inverse_mass_inertia();
        let s = &mut self.state;
        let clock = std::time::Instant::now();
        integrate::integrate(s.dt, im, ii, &mut s.monomers, &mut s.contacts, &mut s.walls);
        self.pass_seconds[0] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        self.neighbours.refresh(&s.monomers.position);
        self.pass_seconds[1] += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        let step = s.step;
        contacts::contacts(
            &s.law,
            s.dt,
            &s.monomers,
            &s.walls,
            &self.neighbours.pairs,
            &mut s.contacts,
            &mut s.tally,
        )
        .map_err(|e| match e {
            EngineError::SlotOverflow {
                kind,
                monomer,
                limit,
                ..
            } => EngineError::SlotOverflow {
                kind,
                step: step + 1,
                monomer,
                limit,
            },
            other => other,
        })?;
        self.pass_seconds[2] += clock.elapsed().as_secs_f64();
        let damping_before = s.monomers.damping_force.clone();
        let wall_force_before = s.wall_force.clone();
        let wall_damping_before = s.wall_damping.clone();
        self.compute_forces();
        // Work over the step by the trapezoid rule, which matches the leap-frog's kinetic
        // energy change exactly up to a bounded, telescoping term.
        let s = &mut self.state;
        let dt = s.dt;
        let m = &s.monomers;
        let mut damping_work = 0.0;
        for i in 0..m.len() {
            damping_work += 0.5 * (damping_before[i] + m.damping_force[i]).dot(m.velocity[i] * dt);
        }
        for (w, wall) in s.walls.iter().enumerate() {
            let travel = wall.velocity * dt;
            damping_work -= 0.5 * (wall_damping_before[w] + s.wall_damping[w]).dot(travel);
            s.wall_work += 0.5 * (wall_force_before[w] + s.wall_force[w]).dot(travel);
        }
        s.tally.damping -= damping_work;
        s.step += 1;
        s.time = simulated_time(s.step, dt);
        if s.step.is_multiple_of(64) {
            self.check_state()?;
        }
        Ok(())
    }

    pub fn run(&mut self, steps: u64) -> Result<(), EngineError> {
        for _ in 0..steps {
            self.step()?;
        }
        Ok(())
    }

    /// Run-time guard: finite positions and velocities, and no overlap above half a radius.
    pub fn check_state(&self) -> Result<(), EngineError> {
        let m = &self.monomers;
        let r = self.law.radius;
        let limit = 0.5 * r;
        for i in 0..m.len() {
            if !(m.position[i].is_finite() && m.velocity[i].is_finite()) {
                return Err(EngineError::NonFinite {
                    step: self.step,
                    monomer: i,
                });
            }
        }
        for i in 0..m.len() {
            for c in self.contacts.pairs_of(i) {
                let overlap = 2.0 * r - (m.position[i] - m.position[c.partner as usize]).length();
                if overlap > limit {
                    return Err(EngineError::RunawayOverlap {
                        step: self.step,
                        monomer: i,
                        partner: format!("monomer {}", c.partner),
                        overlap,
                    });
                }
            }
            for c in self.contacts.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let overlap = crate::model::wall::wall_overlap(m.position[i], w.point, w.normal, r);
                if overlap > limit {
                    return Err(EngineError::RunawayOverlap {
                        step: self.step,
                        monomer: i,
                        partner: format!("the {} wall", w.name),
                        overlap,
                    });
                }
            }
        }
        Ok(())
    }
}

impl Engine for CpuEngine {
    fn law(&self) -> &ContactLaw {
        &self.law
    }
    fn walls(&self) -> &[Wall] {
        &self.walls
    }
    fn monomer_count(&self) -> usize {
        self.monomers.len()
    }
    fn step_count(&self) -> u64 {
        self.step
    }
    fn dt(&self) -> f64 {
        self.dt
    }
    fn advance(&mut self, steps: u64) -> Result<(), EngineError> {
        self.run(steps)
    }
    fn run_mean_wall_force(&mut self, steps: u64) -> Result<Vec<DVec3>, EngineError> {
        let mut sum = vec![DVec3::ZERO; self.walls.len()];
        for _ in 0..steps {
            self.step()?;
            for (s, f) in sum.iter_mut().zip(&self.wall_force) {
                *s += *f;
            }
        }
        Ok(sum.into_iter().map(|s| s / steps.max(1) as f64).collect())
    }
    fn positions(&self) -> Cow<'_, [DVec3]> {
        Cow::Borrowed(&self.monomers.position)
    }
    fn contact_counts(&self) -> (usize, usize) {
        (
            self.contacts.pair_contact_count(),
            self.contacts.wall_contact_count(),
        )
    }
    fn energy(&self) -> EnergyReport {
        self.state.energy()
    }
    fn state(&self) -> Cow<'_, State> {
        Cow::Borrowed(&self.state)
    }
}
