//! CPU reference backend (f64): the same passes, in the same order, as the GPU step script.
//!
//! One step: `integrate` (kick, pointers, twist, drift) → `neighbours` (refresh when stale) →
//! `contacts` (break, form) → `forces` (monomer pairs) → `walls` → work bookkeeping.
//!
//! A leaf: it steps a [`State`] under the [`Engine`] contract and uses nothing of another
//! backend.
//!
//! Every pass is data-parallel (rayon, in whatever thread pool the caller runs it: the global
//! one uses all cores) in the way the device passes are: per-contact work into per-slot
//! results, per-monomer gathers in a fixed order, and sums over monomers per fixed chunk and
//! then over chunks in order. So the state after any number of steps is the same to the bit
//! for any thread count; one thread runs the same code.

pub mod contacts;
pub mod forces;
pub mod integrate;
pub mod memory;
pub mod neighbours;
mod prefetch;
pub mod walls;
pub mod workspace;

use crate::engine::{Engine, EngineError, SKIN_RADII};
use crate::model::ContactLaw;
use crate::state::{simulated_time, Dissipation, EnergyReport, Monomers, State, Wall};
use glam::DVec3;
use neighbours::NeighbourList;
use rayon::prelude::*;
use std::borrow::Cow;
use std::ops::{Deref, DerefMut};
use workspace::{split_len, Workspace, CHUNK};

/// The CPU backend: the state it steps, plus its own search structure (the neighbour list) and
/// timings. It reads as its state (`engine.monomers`, `engine.step`, ...) through `Deref`.
#[derive(Clone, Debug)]
pub struct CpuEngine {
    pub state: State,
    pub neighbours: NeighbourList,
    /// Wall-clock seconds spent in each pass, in [`PASS_NAMES`] order.
    pub pass_seconds: [f64; 5],
    /// Per-slot results and indices the passes reuse; derived from the state each step.
    pub workspace: Workspace,
    /// The damping forces of the step before, for the trapezoid-rule work (reused buffers).
    damping_before: Vec<DVec3>,
}

impl Deref for CpuEngine {
    type Target = State;
    fn deref(&self) -> &State {
        &self.state
    }
}

impl DerefMut for CpuEngine {
    fn deref_mut(&mut self) -> &mut State {
        // The caller may change the contact table: index it again before the next forces.
        self.workspace.partner_index_current = false;
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
            workspace: Workspace::default(),
            damping_before: Vec::new(),
        };
        engine.neighbours.refresh(&engine.state.monomers.position);
        let s = &mut engine.state;
        contacts::contacts(
            &s.law,
            dt,
            &s.monomers,
            &s.walls,
            &engine.neighbours.pairs,
            &engine.neighbours.starts,
            &mut s.contacts,
            &mut s.tally,
        )?;
        // Contacts present at the start are part of the initial state, not a dissipation.
        s.tally = Dissipation::default();
        engine.compute_forces();
        let half = 0.5 * dt;
        let (im, ii) = engine.inverse_mass_inertia();
        let m = &mut engine.state.monomers;
        for i in 0..n {
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
            workspace: Workspace::default(),
            damping_before: Vec::new(),
        }
    }

    /// The damping forces kept for the next step's work (for the memory count).
    pub fn damping_before(&self) -> &Vec<DVec3> {
        &self.damping_before
    }

    fn inverse_mass_inertia(&self) -> (f64, f64) {
        (1.0 / self.law.mass, 1.0 / self.law.moment_of_inertia)
    }

    fn compute_forces(&mut self) {
        let s = &mut self.state;
        let clock = std::time::Instant::now();
        forces::forces(
            &s.law,
            s.dt,
            &mut s.monomers,
            &mut s.contacts,
            &mut s.tally,
            &mut self.workspace,
        );
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
            &mut self.workspace,
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
        let changed = contacts::contacts(
            &s.law,
            s.dt,
            &s.monomers,
            &s.walls,
            &self.neighbours.pairs,
            &self.neighbours.starts,
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
        if changed {
            self.workspace.partner_index_current = false;
        }
        self.pass_seconds[2] += clock.elapsed().as_secs_f64();
        self.damping_before.clone_from(&s.monomers.damping_force);
        let wall_force_before = s.wall_force.clone();
        let wall_damping_before = s.wall_damping.clone();
        self.compute_forces();
        // Work over the step by the trapezoid rule, which matches the leap-frog's kinetic
        // energy change exactly up to a bounded, telescoping term. Summed per chunk, then over
        // chunks in order.
        let s = &mut self.state;
        let dt = s.dt;
        let m = &s.monomers;
        let chunk_work: Vec<f64> = (
            self.damping_before.par_chunks(CHUNK),
            m.damping_force.par_chunks(CHUNK),
            m.velocity.par_chunks(CHUNK),
        )
            .into_par_iter()
            .with_min_len(split_len(m.len(), CHUNK))
            .map(|(before, after, velocity)| {
                let mut work = 0.0;
                for ((b, a), v) in before.iter().zip(after).zip(velocity) {
                    work += 0.5 * (*b + *a).dot(*v * dt);
                }
                work
            })
            .collect();
        let mut damping_work = 0.0;
        for w in chunk_work {
            damping_work += w;
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

    /// Advances `steps` steps. The loop runs on a worker thread of the current rayon pool (the
    /// global one outside any pool): each pass's parallel work is then forked from inside the
    /// pool, not handed over from another thread, which costs a wake-up per pass and, at small
    /// N, more than the pass itself.
    pub fn run(&mut self, steps: u64) -> Result<(), EngineError> {
        rayon::scope(|_| {
            for _ in 0..steps {
                self.step()?;
            }
            Ok(())
        })
    }

    /// Run-time guard: finite positions and velocities, and no overlap above half a radius.
    pub fn check_state(&self) -> Result<(), EngineError> {
        self.first_failure(|i| self.check_finite(i))?;
        self.first_failure(|i| self.check_overlaps(i))
    }

    /// The error of the lowest-numbered monomer `check` rejects, whatever the thread count.
    fn first_failure(
        &self,
        check: impl Fn(usize) -> Result<(), EngineError> + Sync,
    ) -> Result<(), EngineError> {
        let n = self.monomers.len();
        let found: Vec<Option<EngineError>> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .with_min_len(split_len(n, CHUNK))
            .map(|chunk| (chunk * CHUNK..((chunk + 1) * CHUNK).min(n)).find_map(|i| check(i).err()))
            .collect();
        match found.into_iter().flatten().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn check_finite(&self, i: usize) -> Result<(), EngineError> {
        let m = &self.monomers;
        if !(m.position[i].is_finite() && m.velocity[i].is_finite()) {
            return Err(EngineError::NonFinite {
                step: self.step,
                monomer: i,
            });
        }
        Ok(())
    }

    fn check_overlaps(&self, i: usize) -> Result<(), EngineError> {
        let m = &self.monomers;
        let r = self.law.radius;
        let limit = 0.5 * r;
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
        Ok(())
    }
}

impl Engine for CpuEngine {
    fn host_bytes(&self) -> Option<u64> {
        Some(memory::engine_bytes(self))
    }
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
        // On a worker thread, as in `run`.
        rayon::scope(|_| {
            for _ in 0..steps {
                self.step()?;
                for (s, f) in sum.iter_mut().zip(&self.wall_force) {
                    *s += *f;
                }
            }
            Ok::<(), EngineError>(())
        })?;
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
