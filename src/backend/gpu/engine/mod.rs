//! The GPU backend: the CPU reference's passes as WGSL compute shaders on device-resident
//! buffers, driven by a linear step script.
//!
//! The host uploads the state once, then encodes `readback_every` steps (9 dispatches each,
//! one compute pass) per submission and reads back only the small block: overflow flags, the
//! wall forces (current and summed over the batch), contact counts and the energy tally. The
//! full state comes back only on request (tests, snapshots, energy reports).
//!
//! Here: the engine, its construction and its side of the engine contract; `upload`, `script`
//! (the step script and running it), `readback`, `profile` and `error` hold the rest.

mod error;
mod profile;
mod readback;
mod rows;
mod script;
mod transfer;
mod upload;

pub use error::GpuError;

use super::buffers::{Buffers, Sizes};
use super::context::GpuContext;
use super::kernels::Kernels;
use super::layout::{self, GpuConstants, GpuDamping, GpuParams};
use super::shader::Precision;
use crate::engine::{Engine, EngineError, SKIN_RADII};
use crate::model::ContactLaw;
use crate::state::rows::{RowMeasures, RowRequest};
use crate::state::{
    simulated_time, ContactTable, Dissipation, EnergyReport, Monomers, State, Wall,
};
use glam::DVec3;
use std::borrow::Cow;
use std::sync::atomic::{AtomicU64, Ordering};

/// Steps per submission (and between reads of the small block) unless set otherwise.
pub const DEFAULT_READBACK_EVERY: u64 = 100;

/// The small block, as last read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Diagnostics {
    /// Energy tally summed over monomers.
    pub tally: Dissipation,
    pub wall_work: f64,
    pub pair_contacts: usize,
    pub wall_contacts: usize,
    /// Total force of each wall on the monomers at the current step.
    pub wall_force: Vec<DVec3>,
    /// Mean of the per-step wall forces over the steps since the previous read.
    pub mean_wall_force: Vec<DVec3>,
    /// Steps in that mean.
    pub mean_steps: u64,
}

/// The whole simulation state of the GPU backend.
#[derive(Debug)]
pub struct GpuEngine {
    pub ctx: GpuContext,
    pub law: ContactLaw,
    pub dt: f64,
    /// Walls at the current time; the host moves the points by the same additions as the
    /// device (cheaper than reading them back).
    pub walls: Vec<Wall>,
    pub sizes: Sizes,
    /// The arithmetic the kernels were compiled for: the context's ([`GpuContext::precision`]).
    pub precision: Precision,
    /// Most workgroups of a pass over a work list: the device's limit per dimension.
    work_groups_max: u32,
    kernels: Kernels,
    buffers: Buffers,
    /// One per entry point, in Kernel::ALL order.
    bind_groups: Vec<wgpu::BindGroup>,
    pub step: u64,
    /// Simulated time [s], [`simulated_time`] of `step`.
    pub time: f64,
    /// Steps per submission and between reads of the small block.
    pub readback_every: u64,
    diagnostics: Diagnostics,
    /// Running totals of the tally and the wall work, kept on the host in f64: the device's
    /// per-monomer tallies count only since the last read, so a run resumed at a read adds the
    /// same batch sums in the same order as an uninterrupted one (bit-identical totals).
    totals: [f64; layout::TALLY_STRIDE],
    /// The monomers' sample ids, kept on the host: the device never reorders monomers.
    pub(super) ids: Vec<u32>,
    /// Staging buffer of the row measures (grown with the profile they read).
    row_readback: wgpu::Buffer,
    /// Bytes read back from the device so far (every staging read counts).
    read_back: AtomicU64,
}

fn groups(n: usize) -> u32 {
    n.div_ceil(layout::MONOMER_GROUP).max(1) as u32
}

impl GpuEngine {
    /// Builds the engine as the CPU reference's `new` does (same arguments, same initial state):
    /// finds the initial contacts, computes the forces at time 0 and shifts the velocities back
    /// half a step, all on the device.
    pub fn new(
        ctx: GpuContext,
        law: ContactLaw,
        dt: f64,
        monomers: Monomers,
        walls: Vec<Wall>,
        pair_slots: usize,
        wall_slots: usize,
    ) -> Result<Self, GpuError> {
        let n = monomers.len();
        let table = ContactTable::new(n, pair_slots, wall_slots);
        let mut engine = Self::with_state(ctx, law, dt, &monomers, &table, walls)?;
        let mut encoder = engine
            .ctx
            .device
            .create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            engine.encode(&mut pass, &crate::backend::script::START);
        }
        engine.ctx.queue.submit([encoder.finish()]);
        engine.read_small()?;
        // The running wall-force sum starts with the first step.
        engine.clear_wall_force_sum();
        Ok(engine)
    }

    /// An engine holding exactly the given state (forces, torques and velocities as they are:
    /// nothing is recomputed). Per-pass tests start the CPU and the GPU twin from it.
    pub fn with_state(
        ctx: GpuContext,
        law: ContactLaw,
        dt: f64,
        monomers: &Monomers,
        table: &ContactTable,
        walls: Vec<Wall>,
    ) -> Result<Self, GpuError> {
        Self::with_state_laid_out(ctx, law, dt, monomers, table, walls, false)
    }

    /// [`GpuEngine::with_state`] with the per-slot arrays split over three bindings even where
    /// they fit one (`Sizes::split_slots`): the layout large N need, for tests at small N.
    pub fn with_state_laid_out(
        ctx: GpuContext,
        law: ContactLaw,
        dt: f64,
        monomers: &Monomers,
        table: &ContactTable,
        walls: Vec<Wall>,
        split_slots: bool,
    ) -> Result<Self, GpuError> {
        let precision = ctx.precision();
        let sizes = Sizes {
            split_slots,
            split_positions: precision == Precision::Mixed,
            ..Sizes::new(
                monomers.len(),
                walls.len(),
                table.pair_slots,
                table.wall_slots,
            )
        };
        sizes.check(&ctx.device.limits())?;
        let work_groups_max = ctx.device.limits().max_compute_workgroups_per_dimension;
        let kernels = Kernels::new(&ctx, sizes.one_slot_chunk())?;
        let buffers = Buffers::new(&ctx.device, sizes, precision);
        let bind_groups = kernels.bind_groups(&ctx.device, &buffers);
        let row_readback = rows::row_readback_buffer(&ctx.device, 0);
        let mut engine = GpuEngine {
            ctx,
            law,
            dt,
            walls,
            work_groups_max,
            sizes,
            precision,
            kernels,
            buffers,
            bind_groups,
            step: 0,
            time: 0.0,
            readback_every: DEFAULT_READBACK_EVERY,
            diagnostics: Diagnostics::default(),
            totals: [0.0; layout::TALLY_STRIDE],
            ids: monomers.id.clone(),
            row_readback,
            read_back: AtomicU64::new(0),
        };
        engine.upload(monomers, table);
        Ok(engine)
    }

    /// Continues from a complete state (a checkpoint of either backend): the state is uploaded
    /// as it is, and step, time, tally totals and wall forces carry on from it.
    pub fn resume(ctx: GpuContext, state: &State) -> Result<Self, GpuError> {
        let mut engine = Self::with_state(
            ctx,
            state.law,
            state.dt,
            &state.monomers,
            &state.contacts,
            state.walls.clone(),
        )?;
        engine.step = state.step;
        engine.time = simulated_time(state.step, state.dt);
        engine.totals[..7].copy_from_slice(&state.tally.channels());
        engine.totals[7] = state.wall_work;
        engine.read_small()?;
        engine.diagnostics.wall_force = state.wall_force.clone();
        Ok(engine)
    }

    fn params(&self) -> GpuParams {
        let law = &self.law;
        let damping = GpuDamping::from(law.damping);
        GpuParams {
            n: self.sizes.monomers as u32,
            wall_count: self.walls.len() as u32,
            pair_slots: self.sizes.pair_slots as u32,
            wall_slots: self.sizes.wall_slots as u32,
            table_mask: (self.sizes.table - 1) as u32,
            bucket_capacity: self.sizes.bucket_capacity as u32,
            damping_kind: damping.kind,
            slot_chunk: self.sizes.slot_chunk() as u32,
            work_groups_max: self.work_groups_max,
            _pad: 0,
            _pad2: 0,
            _pad3: 0,
            dt: self.dt,
            radius: law.radius,
            inverse_mass: 1.0 / law.mass,
            inverse_inertia: 1.0 / law.moment_of_inertia,
            cell: (2.0 + SKIN_RADII) * law.radius,
            e_star: law.e_star,
            poisson: law.poisson,
            damping_value: damping.value,
            pair: GpuConstants::from(law.pair),
            radius_lo: 0.0,
            two_r_squared: 0.0,
            two_r_squared_lo: 0.0,
        }
        .with_split_radius(self.precision)
    }

    /// The full state (for energy and momentum reports, checkpoints, snapshots and tests). The
    /// tally and wall work are those of the last small-block read; the device keeps no damping
    /// part of the wall forces, so `wall_damping` is zero (a CPU engine continuing from here
    /// books its first step's wall damping work from zero).
    pub fn snapshot(&self) -> State {
        State {
            law: self.law,
            dt: self.dt,
            monomers: self.monomers(),
            contacts: self.contacts(),
            walls: self.current_walls(),
            tally: self.diagnostics.tally,
            wall_work: self.diagnostics.wall_work,
            wall_force: self.diagnostics.wall_force.clone(),
            wall_damping: vec![DVec3::ZERO; self.walls.len()],
            step: self.step,
            time: self.time,
        }
    }

    /// Energy report of the current state (a full readback; rows use
    /// [`GpuEngine::row_measures`]).
    pub fn energy(&self) -> EnergyReport {
        self.snapshot().energy()
    }

    /// Device memory the engine's buffers take [B], as allocated: the layout of its precision
    /// (`Sizes::total_bytes` counts the exact one), the scratch buffers as grown so far.
    pub fn device_bytes(&self) -> u64 {
        self.buffers.device_bytes()
    }

    /// Bytes read back from the device since the engine was made: the small block of every
    /// submission, the row measures and any full reads.
    pub fn bytes_read_back(&self) -> u64 {
        self.read_back.load(Ordering::Relaxed)
    }
}

impl Engine for GpuEngine {
    fn law(&self) -> &ContactLaw {
        &self.law
    }
    fn walls(&self) -> &[Wall] {
        &self.walls
    }
    fn monomer_count(&self) -> usize {
        self.sizes.monomers
    }
    fn step_count(&self) -> u64 {
        self.step
    }
    fn dt(&self) -> f64 {
        self.dt
    }
    fn advance(&mut self, steps: u64) -> Result<(), EngineError> {
        Ok(GpuEngine::run(self, steps)?)
    }
    fn run_mean_wall_force(&mut self, steps: u64) -> Result<Vec<DVec3>, EngineError> {
        Ok(GpuEngine::run_mean_wall_force(self, steps)?)
    }
    fn positions(&self) -> Cow<'_, [DVec3]> {
        Cow::Owned(GpuEngine::positions(self))
    }
    fn contact_counts(&self) -> (usize, usize) {
        (
            self.diagnostics.pair_contacts,
            self.diagnostics.wall_contacts,
        )
    }
    fn energy(&self) -> EnergyReport {
        GpuEngine::energy(self)
    }
    fn state(&self) -> Cow<'_, State> {
        Cow::Owned(self.snapshot())
    }
    fn row_measures(&mut self, request: &RowRequest) -> Result<RowMeasures, EngineError> {
        Ok(GpuEngine::row_measures(self, request)?)
    }
    /// The device still evaluates the corrections' energies (they cost it little); their
    /// host totals become NaN, as the CPU engine's channels do.
    fn stop_tallying_corrections(&mut self) {
        let totals = Dissipation::from_channels(std::array::from_fn(|k| self.totals[k]));
        self.totals[..7].copy_from_slice(&totals.without_corrections().channels());
        self.diagnostics.tally = self.diagnostics.tally.without_corrections();
    }
}
