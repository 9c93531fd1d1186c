//! CPU reference backend (f64): it runs the step script of `backend::script`, the GPU
//! engine's, pass by pass, each pass the CPU function of its entry point's name
//! (`executor.rs`).
//!
//! One step: `integrate_kick`, `integrate_pairs`, `integrate_drift` (leap-frog, pointers,
//! twist; the pair contacts' tests) → `neighbours`, `neighbours_list` (when stale) →
//! `contacts_scan`, `contacts` (events, inelastic limits, wall contacts) → `forces` (monomer
//! pairs) → `wall_forces` (gather, work), `reduce_walls_final` (wall forces). A run of steps
//! (`run`) applies the pair contacts' inelastic limits and evaluates their forces in
//! `integrate_pairs` instead of `contacts` and `forces`, runs `contacts_scan` and `contacts`
//! in one sweep (`run_step_pass`) and joins each step's kick to the gather of the step before;
//! the passes one by one (`run_pass`) stay the device's, and both give the same bits.
//!
//! A leaf: it steps a [`State`] under the [`Engine`] contract and uses nothing of another
//! backend.
//!
//! Every pass is data-parallel (rayon, in whatever thread pool the caller runs it: the global
//! one uses all cores) in the way the device passes are: per-contact work into per-slot
//! results, per-monomer gathers in a fixed order, and sums over monomers per fixed chunk and
//! then over chunks in order. So the state after any number of steps is the same to the bit
//! for any thread count; one thread runs the same code.
//!
//! The modules are layers, each naming only those below it (tests/module_cycles.rs holds them
//! to it; DESIGN.md, "CPU engine layers"):
//!
//! 1. `lanes/` (four f64 lanes, the choice of instructions), `chunking.rs` (the fixed
//!    chunks), `prefetch.rs` (the hints), `memory.rs` (bytes of arrays);
//! 2. `law/`: the contact law contact by contact, one at a time and four at a time;
//! 3. `partner_index.rs`, `workspace.rs`: what the passes hand each other;
//! 4. `passes/`: the passes of the step script (the neighbour list with its own);
//! 5. `executor.rs` and this file: the engine that runs them.

pub mod chunking;
mod executor;
pub mod lanes;
pub mod law;
pub mod memory;
pub mod partner_index;
pub mod passes;
pub mod prefetch;
pub mod workspace;

use crate::backend::script::{Kernel, START, STEP};
use crate::engine::{Engine, EngineError, SKIN_RADII};
use crate::model::ContactLaw;
use crate::state::{simulated_time, EnergyReport, Monomers, State, Wall};
use chunking::{split_len, CHUNK, SERIAL_BELOW};
use glam::DVec3;
use passes::neighbours::NeighbourList;
use rayon::prelude::*;
use std::borrow::Cow;
use std::ops::{Deref, DerefMut};
use std::sync::atomic::{AtomicBool, Ordering};
use workspace::Workspace;

/// The CPU backend: the state it steps, plus its own search structure (the neighbour list) and
/// timings. It reads as its state (`engine.monomers`, `engine.step`, ...) through `Deref`.
#[derive(Clone, Debug)]
pub struct CpuEngine {
    pub state: State,
    pub neighbours: NeighbourList,
    /// Wall-clock seconds spent in each pass, in [`PASS_NAMES`] order.
    pub pass_seconds: [f64; 5],
    /// Per-slot results, indices and work lists the passes hand each other; derived from the
    /// state each step.
    pub workspace: Workspace,
}

impl Deref for CpuEngine {
    type Target = State;
    fn deref(&self) -> &State {
        &self.state
    }
}

impl DerefMut for CpuEngine {
    fn deref_mut(&mut self) -> &mut State {
        // The caller may change the contact table: index it again before the next forces, and
        // mark the candidates that are partners again before the next scan.
        self.workspace.partner_index_current = false;
        self.workspace.results_of_step = false;
        self.neighbours.partners_current = false;
        &mut self.state
    }
}

/// The passes of one step, timed in these groups.
pub const PASS_NAMES: [&str; 5] = ["integrate", "neighbours", "contacts", "forces", "walls"];

/// The group of [`PASS_NAMES`] a pass is timed in.
fn timing_group(pass: Kernel) -> usize {
    match pass.entry() {
        e if e.starts_with("integrate") => 0,
        e if e.starts_with("neighbours") => 1,
        e if e.starts_with("contacts") => 2,
        "forces" | "forces_corrections" => 3,
        _ => 4,
    }
}

/// Marks a run's steps over ([`keep_awake`]'s `done`) when dropped.
struct Ending<'a>(&'a AtomicBool);

impl Drop for Ending<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// Runs the pool's pending jobs on the thread that takes this one, spinning between them, until
/// `done`: between two passes of a run the pool's other thread then waits awake for the next
/// pass's chunks instead of falling asleep at a pass's tail and being woken for the next one
/// (on a virtual machine a wake-up can cost more than a small pass; docs/guide/src/
/// benchmarks.md, "CPU engine: a thread kept awake"). Taken by the runner's own thread (`runner`), it returns at
/// once: that thread waits on nothing but its own passes.
fn keep_awake(done: &AtomicBool, runner: Option<usize>) {
    if rayon::current_thread_index() == runner {
        return;
    }
    while !done.load(Ordering::Acquire) {
        if rayon::yield_now() != Some(rayon::Yield::Executed) {
            std::hint::spin_loop();
        }
    }
}

fn neighbour_list(law: &ContactLaw) -> NeighbourList {
    NeighbourList::new(2.0 * law.radius, SKIN_RADII * law.radius)
}

impl CpuEngine {
    /// Builds the engine with synchronised initial velocities `monomers.velocity` (time 0):
    /// runs the start script ([`START`]): the initial contacts, the forces at time 0, and the
    /// velocities shifted back half a step, as the leap-frog stores them.
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
        };
        engine.workspace.pair_tests = vec![0; n];
        for pass in START {
            engine.run_pass(pass)?;
        }
        Ok(engine)
    }

    /// An engine holding exactly the given state, nothing recomputed (a checkpoint's, or one
    /// another backend computed); its neighbour list is built from the positions and its pair
    /// tests made on the state as it is (`contacts_pair_tests`, as the device after an upload).
    pub fn from_state(state: State) -> Self {
        let mut neighbours = neighbour_list(&state.law);
        neighbours.build(&state.monomers.position);
        let mut engine = CpuEngine {
            state,
            neighbours,
            pass_seconds: [0.0; 5],
            workspace: Workspace::default(),
        };
        engine
            .run_pass(Kernel::ContactsPairTests)
            .expect("the pair tests cannot fail");
        engine
    }

    /// Advances one time step: the passes of [`STEP`].
    pub fn step(&mut self) -> Result<(), EngineError> {
        self.step_joined(false, false)
    }

    /// One step of a run of several: `kicked` where the step before has done this one's kick
    /// (joined to its gather), `kick_next` to join the next step's kick to this one's gather
    /// (`wall_forces` with a [`passes::integrate::NextKick`]). A run ends on a step whose velocities are
    /// the leap-frog's v(n+½), as after [`Self::step`].
    fn step_joined(&mut self, kicked: bool, kick_next: bool) -> Result<(), EngineError> {
        let step = self.step;
        for pass in STEP {
            if kicked && pass == Kernel::IntegrateKick {
                continue;
            }
            let clock = std::time::Instant::now();
            let done = if kick_next && pass == Kernel::WallForces {
                self.wall_forces_then_kick()
            } else {
                self.run_step_pass(pass)
            };
            done.map_err(|e| e.at_step(step + 1))?;
            self.pass_seconds[timing_group(pass)] += clock.elapsed().as_secs_f64();
        }
        let s = &mut self.state;
        s.step += 1;
        s.time = simulated_time(s.step, s.dt);
        if s.step.is_multiple_of(64) {
            self.check_state()?;
        }
        Ok(())
    }

    /// Advances `steps` steps. The loop runs on a worker thread of the current rayon pool (the
    /// global one outside any pool): each pass's parallel work is then forked from inside the
    /// pool, not handed over from another thread, which costs a wake-up per pass and, at small
    /// N, more than the pass itself. The pool's other threads are kept awake meanwhile
    /// ([`keep_awake`]), so that no pass waits for one to wake.
    pub fn run(&mut self, steps: u64) -> Result<(), EngineError> {
        let done = AtomicBool::new(false);
        rayon::scope(|scope| {
            let runner = rayon::current_thread_index();
            // Below `SERIAL_BELOW` every pass runs on the runner: nothing to keep awake for.
            let others = match self.monomers.len() >= SERIAL_BELOW {
                true => rayon::current_num_threads() - 1,
                false => 0,
            };
            for _ in 0..others {
                let done = &done;
                scope.spawn(move |_| keep_awake(done, runner));
            }
            // Ends the keeper however the steps end (an error, a panic): the scope waits for it.
            let _ending = Ending(&done);
            self.run_steps(steps, |_| {})
        })
    }

    /// `steps` steps, each but the last with the next one's kick joined to its gather;
    /// `after_each` sees the engine after every step (its velocities a half step ahead of
    /// the positions' time but for the last).
    fn run_steps(
        &mut self,
        steps: u64,
        mut after_each: impl FnMut(&Self),
    ) -> Result<(), EngineError> {
        for k in 0..steps {
            self.step_joined(k > 0, k + 1 < steps)?;
            after_each(self);
        }
        Ok(())
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
        let (neighbours, workspace) = (self.neighbours.heap_bytes(), self.workspace.heap_bytes());
        Some(memory::state_bytes(&self.state) + neighbours + workspace)
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
            self.run_steps(steps, |e| {
                for (s, f) in sum.iter_mut().zip(&e.wall_force) {
                    *s += *f;
                }
            })
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
    fn stop_tallying_corrections(&mut self) {
        self.state.tally = self.state.tally.without_corrections();
    }
}
