//! The GPU backend: the CPU reference's passes as WGSL compute shaders on device-resident
//! buffers, driven by a linear step script.
//!
//! The host uploads the state once, then encodes `readback_every` steps (9 dispatches each,
//! one compute pass) per submission and reads back only the small block: overflow flags, the
//! wall forces (current and summed over the batch), contact counts and the energy tally. The
//! full state comes back only on request (tests, snapshots, energy reports).

use super::buffers::{Buffers, SizeError, Sizes};
use super::context::{ContextError, GpuContext};
use super::kernels::{Kernel, Kernels};
use super::layout::{self, vec4, GpuConstants, GpuDamping, GpuParams, GpuWall};
use super::shader::ShaderError;
use crate::engine::{Engine, EngineError, SKIN_RADII};
use crate::model::ContactLaw;
use crate::state::interaction::wall_interaction;
use crate::state::{
    ContactTable, Dissipation, EnergyReport, Monomers, PairContact, State, Wall, WallContact,
};
use glam::DVec3;
use std::borrow::Cow;
use std::fmt;

/// Steps per submission (and between reads of the small block) unless set otherwise.
pub const DEFAULT_READBACK_EVERY: u64 = 100;

/// Everything that can stop the GPU engine.
#[derive(Debug)]
pub enum GpuError {
    Context(ContextError),
    Shader(ShaderError),
    Size(SizeError),
    /// Slot overflow or a non-finite state, as the CPU engine reports them.
    Engine(EngineError),
    /// More monomers hashed to one bucket of the cell table than it holds.
    BucketOverflow {
        monomer: usize,
        capacity: usize,
    },
    /// More candidate partners within 2r + skin than a candidate list holds.
    NeighbourOverflow {
        monomer: usize,
        capacity: usize,
    },
    /// The device was lost or reported an error: nothing on it can be trusted or read.
    DeviceLost(String),
    /// More contacts with owners of lower index than the gather list holds.
    IncomingOverflow {
        monomer: usize,
        capacity: usize,
    },
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GpuError::Context(e) => write!(f, "{e}"),
            GpuError::Shader(e) => write!(f, "{e}"),
            GpuError::Size(e) => write!(f, "{e}"),
            GpuError::Engine(e) => write!(f, "{e}"),
            GpuError::BucketOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} found its cell-table bucket full ({capacity} ids); monomers \
                 overlap far beyond contact, or raise gpu::buffers::DEFAULT_BUCKET_CAPACITY"
            ),
            GpuError::NeighbourOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} has more than {capacity} candidate partners within 2r + skin \
                 (gpu::layout::NEIGHBOUR_CAPACITY); monomers overlap far beyond contact"
            ),
            GpuError::DeviceLost(why) => write!(f, "the GPU failed: {why}"),
            GpuError::IncomingOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} has more than {capacity} contacts with lower-index monomers \
                 (gpu::layout::INCOMING_CAPACITY); monomers overlap far beyond contact"
            ),
        }
    }
}

impl std::error::Error for GpuError {}

impl From<ContextError> for GpuError {
    fn from(e: ContextError) -> Self {
        GpuError::Context(e)
    }
}
impl From<ShaderError> for GpuError {
    fn from(e: ShaderError) -> Self {
        GpuError::Shader(e)
    }
}
impl From<SizeError> for GpuError {
    fn from(e: SizeError) -> Self {
        GpuError::Size(e)
    }
}
impl From<EngineError> for GpuError {
    fn from(e: EngineError) -> Self {
        GpuError::Engine(e)
    }
}

/// The engine contract's error: a guard the device raised is the engine's own, a lost device
/// is `DeviceLost`, everything else the GPU's error as it is.
impl From<GpuError> for EngineError {
    fn from(e: GpuError) -> Self {
        match e {
            GpuError::Engine(e) => e,
            GpuError::DeviceLost(why) => EngineError::DeviceLost(why),
            other => EngineError::Backend(Box::new(other)),
        }
    }
}

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
    /// Most workgroups of a pass over a work list: the device's limit per dimension.
    work_groups_max: u32,
    kernels: Kernels,
    buffers: Buffers,
    /// One per entry point, in kernels::ENTRY_POINTS order.
    bind_groups: Vec<wgpu::BindGroup>,
    pub step: u64,
    pub time: f64,
    /// Steps per submission and between reads of the small block.
    pub readback_every: u64,
    diagnostics: Diagnostics,
    /// Running totals of the tally and the wall work, kept on the host in f64: the device's
    /// per-monomer tallies count only since the last read, so a run resumed at a read adds the
    /// same batch sums in the same order as an uninterrupted one (bit-identical totals).
    totals: [f64; layout::TALLY_STRIDE],
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
            engine.encode(
                &mut pass,
                &[
                    Kernel::Neighbours,
                    Kernel::NeighboursList,
                    Kernel::ContactsScan,
                    Kernel::Contacts,
                    Kernel::ContactsClearTally,
                    Kernel::Forces,
                    Kernel::WallForces,
                    Kernel::ReduceWallsFinal,
                    Kernel::IntegrateClearWork,
                    Kernel::IntegrateStart,
                ],
            );
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
        let sizes = Sizes {
            split_slots,
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
        let buffers = Buffers::new(&ctx.device, sizes);
        let bind_groups = kernels.bind_groups(&ctx.device, &buffers);
        let mut engine = GpuEngine {
            ctx,
            law,
            dt,
            walls,
            work_groups_max,
            sizes,
            kernels,
            buffers,
            bind_groups,
            step: 0,
            time: 0.0,
            readback_every: DEFAULT_READBACK_EVERY,
            diagnostics: Diagnostics::default(),
            totals: [0.0; layout::TALLY_STRIDE],
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
        engine.time = state.time;
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
        }
    }

    fn write<T: bytemuck::Pod>(&self, name: &str, data: &[T]) {
        if !data.is_empty() {
            self.ctx
                .queue
                .write_buffer(self.buffers.get(name), 0, bytemuck::cast_slice(data));
        }
    }

    /// Writes a per-slot vector array to its chunk bindings.
    fn write_slots(&self, array: &str, data: &[[f64; 4]]) {
        for (c, part) in data.chunks(self.sizes.slot_chunk()).enumerate() {
            self.write(&format!("{array}_{c}"), part);
        }
    }

    /// Writes the whole state to the device; tallies, flags and the diagnostics block start
    /// from zero (flags from "none").
    pub fn upload(&mut self, m: &Monomers, table: &ContactTable) {
        let n = m.len();
        let v4 = |v: &[DVec3]| v.iter().map(|x| vec4(*x)).collect::<Vec<_>>();
        self.write("params", &[self.params()]);
        let walls: Vec<GpuWall> = self
            .walls
            .iter()
            .map(|w| GpuWall {
                point: vec4(w.point),
                normal: vec4(w.normal),
                velocity: vec4(w.velocity),
                k: GpuConstants::from(w.constants),
            })
            .collect();
        self.write("walls", &walls);
        self.write("position", &v4(&m.position));
        self.write("velocity", &v4(&m.velocity));
        self.write("angular_velocity", &v4(&m.angular_velocity));
        self.write("force", &v4(&m.force));
        self.write("torque", &v4(&m.torque));
        self.write("damping_force", &v4(&m.damping_force));
        // The previous step's wall powers of each monomer (Σ_w F·v_w dt and its damping part).
        let mut aux = Vec::with_capacity(n);
        for i in 0..n {
            let (mut p, mut q) = (0.0, 0.0);
            for c in table.walls_of(i) {
                let w = &self.walls[c.wall as usize];
                let (f, fd, _) = wall_interaction(&self.law, m.position[i], m.velocity[i], w, c);
                p += f.dot(w.velocity * self.dt);
                q += fd.dot(w.velocity * self.dt);
            }
            aux.push([m.inverse_mass_scale[i], m.inverse_inertia_scale[i], p, q]);
        }
        self.write("aux", &aux);
        self.write("tally", &vec![0.0f64; n * layout::TALLY_STRIDE]);
        let n1: Vec<[f64; 4]> = table
            .pair
            .iter()
            .map(|c| [c.n1.x, c.n1.y, c.n1.z, c.twist])
            .collect();
        let n2: Vec<[f64; 4]> = table.pair.iter().map(|c| vec4(c.n2)).collect();
        let partner: Vec<u32> = table.pair.iter().map(|c| c.partner).collect();
        self.write_slots("pair_n1", &n1);
        self.write_slots("pair_n2", &n2);
        self.write("pair_partner", &partner);
        self.write("pair_count", &table.pair_count);
        let wn1: Vec<[f64; 4]> = table
            .wall
            .iter()
            .map(|c| [c.n1.x, c.n1.y, c.n1.z, c.twist])
            .collect();
        let anchor: Vec<[f64; 4]> = table.wall.iter().map(|c| vec4(c.anchor)).collect();
        let wall_id: Vec<u32> = table.wall.iter().map(|c| c.wall).collect();
        self.write("wall_n1", &wn1);
        self.write("wall_anchor", &anchor);
        self.write("wall_id", &wall_id);
        self.write("wall_count", &table.wall_count);
        self.write("incoming_count", &vec![0u32; n]);
        // The candidate lists are built at the first neighbour passes.
        let mut flags = [layout::NO_MONOMER; layout::FLAG_COUNT];
        flags[layout::FLAG_REBUILD] = 0;
        self.write("flags", &flags);
        self.write("neighbour_count", &vec![0u32; n]);
        self.write("reference_position", &v4(&m.position));
        self.write("diag", &[0.0f64; layout::DIAG_SIZE]);
        // The lists of a finished step: event lists empty (no entries, dispatches of no
        // workgroups), the pair-contact list holding every contact of the table.
        let contact_list: Vec<u32> = (0..n)
            .flat_map(|i| {
                let first = (i * table.pair_slots) as u32;
                first..first + table.pair_count[i]
            })
            .collect();
        let pair_groups =
            (contact_list.len().div_ceil(layout::PAIR_GROUP) as u32).min(self.work_groups_max);
        self.write("contact_list", &contact_list);
        let mut work = [0u32; layout::WORK_LISTS];
        work[layout::WORK_PAIRS] = contact_list.len() as u32;
        self.write("work", &work);
        let mut args = [0u32, 1, 1].repeat(layout::ARGS_REBUILD + 1);
        args[3 * layout::WORK_PAIRS] = pair_groups;
        // The candidate lists are built at the first neighbour passes (FLAG_REBUILD above).
        args[3 * layout::ARGS_REBUILD] = groups(n);
        self.write("work_args", &args);
        // The pair contacts' tests for a first contacts_scan, which no integrate_pairs precedes.
        self.write("pair_tests", &vec![0u32; n]);
        self.dispatch(&[Kernel::ContactsPairTests]);
    }

    /// Empties the work lists, as integrate_drift does before each step's scan (tests that
    /// run contacts_scan on an uploaded state, whose lists are those of a finished step).
    pub fn clear_work_lists(&self) {
        self.write("work", &[0u32; layout::WORK_LISTS]);
        self.write("work_args", &[0u32, 1, 1].repeat(layout::WORK_LISTS));
    }

    fn encode(&self, pass: &mut wgpu::ComputePass<'_>, kernels: &[Kernel]) {
        let n = self.sizes.monomers;
        for &k in kernels {
            pass.set_pipeline(self.kernels.pipeline(k));
            pass.set_bind_group(0, &self.bind_groups[k as usize], &[]);
            if let Some(offset) = k.indirect_offset() {
                // Sized on the device by the scan that filled the list.
                pass.dispatch_workgroups_indirect(self.buffers.get("work_args"), offset);
                continue;
            }
            let count = match k {
                Kernel::IntegrateDrift => groups(n.max(self.walls.len())),
                Kernel::ReduceWallsFinal | Kernel::ReduceDiagnostics => 1,
                _ => groups(n),
            };
            pass.dispatch_workgroups(count, 1, 1);
        }
    }

    /// Lowers the most workgroups a pass over a work list is dispatched with, so that tests
    /// on small systems walk the lists with a stride as the largest systems do.
    pub fn limit_work_groups(&mut self, max: u32) {
        self.work_groups_max = max.clamp(1, self.work_groups_max);
        self.write("params", &[self.params()]);
        // The pair-contact list's dispatch as contacts_scan would size it now.
        let pairs = self.read::<u32>("work", layout::WORK_LISTS)[layout::WORK_PAIRS];
        let groups = (pairs as usize).div_ceil(layout::PAIR_GROUP) as u32;
        self.ctx.queue.write_buffer(
            self.buffers.get("work_args"),
            (12 * layout::WORK_PAIRS) as u64,
            bytemuck::cast_slice(&[groups.min(self.work_groups_max)]),
        );
    }

    /// The dispatches of one step, in order. `contacts_scan` lists the owners with contact
    /// events, a contact beyond an inelastic limit or wall contacts, and `contacts` runs over
    /// that list only
    /// (an indirect dispatch sized on the device); `wall_forces` also sums the wall forces per
    /// block, which `reduce_walls_final` adds up.
    pub const STEP: [Kernel; 10] = [
        Kernel::IntegrateKick,
        Kernel::IntegratePairs,
        Kernel::IntegrateDrift,
        Kernel::Neighbours,
        Kernel::NeighboursList,
        Kernel::ContactsScan,
        Kernel::Contacts,
        Kernel::Forces,
        Kernel::WallForces,
        Kernel::ReduceWallsFinal,
    ];

    /// Every kernel a submission of several steps runs, in step order: those of
    /// [`GpuEngine::STEP`], and after the kick `integrate_kick_with_wall_sums`, which starts
    /// each step but the first and does the last step's `reduce_walls_final` on the way.
    pub fn passes() -> Vec<Kernel> {
        Self::STEP
            .into_iter()
            .flat_map(|k| match k {
                Kernel::IntegrateKick => vec![k, Kernel::IntegrateKickWithWallSums],
                other => vec![other],
            })
            .collect()
    }

    /// The dispatches of step `s` (from 0) of a submission of `steps` steps: inside a
    /// submission the wall sums of a step are added by the next step's kick (a dispatch fewer
    /// per step; on lavapipe each costs tens of µs), and the submission ends where a step of
    /// [`GpuEngine::STEP`] ends, so the small block read after it is complete.
    pub fn step_script(s: u64, steps: u64) -> impl Iterator<Item = Kernel> {
        let first = s == 0;
        let last = s + 1 == steps;
        Self::STEP.into_iter().filter_map(move |k| match k {
            Kernel::IntegrateKick if !first => Some(Kernel::IntegrateKickWithWallSums),
            Kernel::ReduceWallsFinal if !last => None,
            other => Some(other),
        })
    }

    /// Runs the given kernels once, in order, in one submission, and waits (tests of a pass).
    pub fn dispatch(&mut self, kernels: &[Kernel]) {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode(&mut pass, kernels);
        }
        self.ctx.queue.submit([encoder.finish()]);
        self.wait().expect("the device failed during a pass test");
    }

    fn wait(&self) -> Result<(), GpuError> {
        let polled = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        match (self.ctx.failure(), polled) {
            (Some(why), _) => Err(GpuError::DeviceLost(why)),
            (None, Err(e)) => Err(GpuError::DeviceLost(e.to_string())),
            (None, Ok(_)) => Ok(()),
        }
    }

    /// Advances one step (one submission: prefer [`GpuEngine::run`]).
    pub fn step(&mut self) -> Result<(), GpuError> {
        self.run(1)
    }

    /// Advances `steps` steps, `readback_every` per submission, reading the small block after
    /// each submission. An overflow or a non-finite state stops the run at the end of the
    /// submission in which it happened.
    pub fn run(&mut self, steps: u64) -> Result<(), GpuError> {
        let mut left = steps;
        while left > 0 {
            let batch = left.min(self.readback_every.max(1));
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                for s in 0..batch {
                    let script: Vec<Kernel> = Self::step_script(s, batch).collect();
                    self.encode(&mut pass, &script);
                }
            }
            self.ctx.queue.submit([encoder.finish()]);
            self.advanced(batch)?;
            left -= batch;
        }
        Ok(())
    }

    /// Host side of `steps` steps just submitted: walls, step, time, and the small block.
    fn advanced(&mut self, steps: u64) -> Result<(), GpuError> {
        // The device moves the walls the same way, so these points equal its own.
        for _ in 0..steps {
            for w in &mut self.walls {
                w.point += w.velocity * self.dt;
            }
        }
        self.step += steps;
        self.time += steps as f64 * self.dt;
        self.read_small()?;
        self.clear_wall_force_sum();
        Ok(())
    }

    /// Advances `steps` ordinary steps (one submission, at most 227) with a timestamp before
    /// and after every dispatch, and returns the mean seconds per step of each kernel of
    /// [`GpuEngine::passes`] (`integrate_kick` and `reduce_walls_final` run once per
    /// submission); `None` where the device lacks timestamp queries inside passes.
    pub fn profile_passes(&mut self, steps: u32) -> Result<Option<Vec<(Kernel, f64)>>, GpuError> {
        let device = &self.ctx.device;
        if !device.features().contains(super::context::TIMING_FEATURES) {
            return Ok(None);
        }
        let script: Vec<Kernel> = (0..u64::from(steps))
            .flat_map(|s| Self::step_script(s, u64::from(steps)))
            .collect();
        let count = 2 * script.len() as u32;
        assert!(
            count <= wgpu::QUERY_SET_MAX_QUERIES,
            "too many steps to profile"
        );
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass times"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let bytes = u64::from(count) * 8;
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass times"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass times readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            for (q, &k) in script.iter().enumerate() {
                let query = 2 * q as u32;
                pass.write_timestamp(&queries, query);
                self.encode(&mut pass, &[k]);
                pass.write_timestamp(&queries, query + 1);
            }
        }
        encoder.resolve_query_set(&queries, 0..count, &resolved, 0);
        encoder.copy_buffer_to_buffer(&resolved, 0, &staging, 0, bytes);
        self.ctx.queue.submit([encoder.finish()]);
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&map_read(&self.ctx, &staging, bytes)?);
        let period = f64::from(self.ctx.queue.get_timestamp_period()) * 1e-9;
        let passes = Self::passes();
        let mut seconds = vec![0.0; passes.len()];
        for (k, pair) in script.iter().zip(ticks.chunks_exact(2)) {
            let at = passes.iter().position(|p| p == k).expect("a pass");
            seconds[at] += pair[1].saturating_sub(pair[0]) as f64 * period;
        }
        self.advanced(u64::from(steps))?;
        Ok(Some(
            passes
                .iter()
                .zip(seconds)
                .map(|(&k, s)| (k, s / f64::from(steps)))
                .collect(),
        ))
    }

    fn clear_wall_force_sum(&self) {
        let zeros = [0.0f64; layout::DIAG_SIZE - layout::DIAG_WALL_FORCE_SUM];
        self.ctx.queue.write_buffer(
            self.buffers.get("diag"),
            (layout::DIAG_WALL_FORCE_SUM * 8) as u64,
            bytemuck::cast_slice(&zeros),
        );
        self.ctx.queue.write_buffer(
            self.buffers.get("diag"),
            (layout::DIAG_STEPS * 8) as u64,
            bytemuck::bytes_of(&0.0f64),
        );
    }

    /// Reduces the tallies and counts, reads flags and the diagnostics block, and turns a raised
    /// flag into its error.
    fn read_small(&mut self) -> Result<(), GpuError> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode(&mut pass, &[Kernel::ReduceDiagnostics]);
        }
        let flag_bytes = (layout::FLAG_COUNT * 4) as u64;
        let flags_at = 0;
        let diag_at = flag_bytes.next_multiple_of(8);
        encoder.copy_buffer_to_buffer(
            self.buffers.get("flags"),
            0,
            &self.buffers.small_readback,
            flags_at,
            flag_bytes,
        );
        encoder.copy_buffer_to_buffer(
            self.buffers.get("diag"),
            0,
            &self.buffers.small_readback,
            diag_at,
            (layout::DIAG_SIZE * 8) as u64,
        );
        // Counted from here on: the totals live on the host.
        encoder.clear_buffer(self.buffers.get("tally"), 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        let bytes = map_read(
            &self.ctx,
            &self.buffers.small_readback,
            Buffers::small_bytes(),
        )?;
        let flags: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes[..flag_bytes as usize]);
        let diag: Vec<f64> = bytemuck::pod_collect_to_vec(&bytes[diag_at as usize..]);
        for (total, since) in self.totals.iter_mut().zip(&diag[..layout::TALLY_STRIDE]) {
            *total += since;
        }
        let t = &self.totals;
        let nw = self.walls.len();
        let wall = |base: usize, w: usize| {
            DVec3::new(
                diag[base + 4 * w],
                diag[base + 4 * w + 1],
                diag[base + 4 * w + 2],
            )
        };
        let steps = diag[layout::DIAG_STEPS];
        self.diagnostics = Diagnostics {
            tally: Dissipation::from_channels(std::array::from_fn(|k| t[k])),
            wall_work: t[7],
            pair_contacts: diag[layout::DIAG_PAIR_CONTACTS] as usize,
            wall_contacts: diag[layout::DIAG_WALL_CONTACTS] as usize,
            wall_force: (0..nw).map(|w| wall(layout::DIAG_WALL_FORCE, w)).collect(),
            mean_wall_force: (0..nw)
                .map(|w| wall(layout::DIAG_WALL_FORCE_SUM, w) / steps.max(1.0))
                .collect(),
            mean_steps: steps as u64,
        };
        let raised = |f: usize| (flags[f] != layout::NO_MONOMER).then_some(flags[f] as usize);
        if let Some(monomer) = raised(layout::FLAG_PAIR_SLOTS) {
            return Err(EngineError::SlotOverflow {
                kind: "monomer-monomer",
                // Flags are read once per batch: the overflow happened within it.
                step: self.step,
                monomer,
                limit: self.sizes.pair_slots,
            }
            .into());
        }
        if let Some(monomer) = raised(layout::FLAG_WALL_SLOTS) {
            return Err(EngineError::SlotOverflow {
                kind: "monomer-wall",
                step: self.step,
                monomer,
                limit: self.sizes.wall_slots,
            }
            .into());
        }
        if let Some(monomer) = raised(layout::FLAG_BUCKET) {
            return Err(GpuError::BucketOverflow {
                monomer,
                capacity: self.sizes.bucket_capacity,
            });
        }
        if let Some(monomer) = raised(layout::FLAG_NEIGHBOURS) {
            return Err(GpuError::NeighbourOverflow {
                monomer,
                capacity: layout::NEIGHBOUR_CAPACITY,
            });
        }
        if let Some(monomer) = raised(layout::FLAG_INCOMING) {
            return Err(GpuError::IncomingOverflow {
                monomer,
                capacity: layout::INCOMING_CAPACITY,
            });
        }
        if let Some(monomer) = raised(layout::FLAG_NON_FINITE) {
            return Err(EngineError::NonFinite {
                step: self.step,
                monomer,
            }
            .into());
        }
        Ok(())
    }

    /// Reads the small block now (after [`GpuEngine::dispatch`] of single passes).
    pub fn refresh_diagnostics(&mut self) -> Result<&Diagnostics, GpuError> {
        self.read_small()?;
        Ok(&self.diagnostics)
    }

    /// The small block as last read (after `new` and after every submission of `run`).
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.diagnostics
    }

    /// Total force each wall exerts on the monomers at the current time.
    pub fn wall_force(&self) -> &[DVec3] {
        &self.diagnostics.wall_force
    }

    fn read<T: bytemuck::Pod>(&self, name: &str, count: usize) -> Vec<T> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        if bytes == 0 {
            return Vec::new();
        }
        let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("state readback"),
            size: bytes.next_multiple_of(8),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(
            self.buffers.get(name),
            0,
            &staging,
            0,
            bytes.next_multiple_of(8),
        );
        self.ctx.queue.submit([encoder.finish()]);
        // Full-state reads come after a successful read of the small block; a device failing
        // in between is a narrow race, reported here with what failed.
        let raw = map_read(&self.ctx, &staging, bytes.next_multiple_of(8))
            .unwrap_or_else(|e| panic!("reading `{name}` back from the GPU: {e}"));
        bytemuck::pod_collect_to_vec(&raw[..bytes as usize])
    }

    /// A per-slot vector array, gathered from its chunk bindings.
    fn read_slots(&self, array: &str, count: usize) -> Vec<[f64; 4]> {
        let chunk = self.sizes.slot_chunk();
        let mut out = Vec::with_capacity(count);
        for c in 0..layout::SLOT_CHUNKS {
            let part = count.saturating_sub(c * chunk).min(chunk);
            if part == 0 {
                break;
            }
            out.extend(self.read::<[f64; 4]>(&format!("{array}_{c}"), part));
        }
        out
    }

    fn read_vec3(&self, name: &str, count: usize) -> Vec<DVec3> {
        self.read::<[f64; 4]>(name, count)
            .into_iter()
            .map(|v| DVec3::new(v[0], v[1], v[2]))
            .collect()
    }

    /// Positions at the current time (a full-array readback).
    pub fn positions(&self) -> Vec<DVec3> {
        self.read_vec3("position", self.sizes.monomers)
    }

    /// The monomers as the CPU engine stores them.
    pub fn monomers(&self) -> Monomers {
        let n = self.sizes.monomers;
        let aux: Vec<[f64; 4]> = self.read("aux", n);
        Monomers {
            position: self.positions(),
            velocity: self.read_vec3("velocity", n),
            angular_velocity: self.read_vec3("angular_velocity", n),
            force: self.read_vec3("force", n),
            torque: self.read_vec3("torque", n),
            damping_force: self.read_vec3("damping_force", n),
            inverse_mass_scale: aux.iter().map(|a| a[0]).collect(),
            inverse_inertia_scale: aux.iter().map(|a| a[1]).collect(),
        }
    }

    /// The contact history as the CPU engine stores it (slots beyond the counts are whatever
    /// the device left there).
    pub fn contacts(&self) -> ContactTable {
        let n = self.sizes.monomers;
        let (ps, ws) = (self.sizes.pair_slots, self.sizes.wall_slots);
        let mut table = ContactTable::new(n, ps, ws);
        let n1 = self.read_slots("pair_n1", n * ps);
        let n2 = self.read_slots("pair_n2", n * ps);
        let partner: Vec<u32> = self.read("pair_partner", n * ps);
        table.pair_count = self.read("pair_count", n);
        for (k, c) in table.pair.iter_mut().enumerate() {
            *c = PairContact {
                partner: partner[k],
                n1: DVec3::new(n1[k][0], n1[k][1], n1[k][2]),
                n2: DVec3::new(n2[k][0], n2[k][1], n2[k][2]),
                twist: n1[k][3],
            };
        }
        let wn1: Vec<[f64; 4]> = self.read("wall_n1", n * ws);
        let anchor: Vec<[f64; 4]> = self.read("wall_anchor", n * ws);
        let wall_id: Vec<u32> = self.read("wall_id", n * ws);
        table.wall_count = self.read("wall_count", n);
        for (k, c) in table.wall.iter_mut().enumerate() {
            *c = WallContact {
                wall: wall_id[k],
                n1: DVec3::new(wn1[k][0], wn1[k][1], wn1[k][2]),
                anchor: DVec3::new(anchor[k][0], anchor[k][1], anchor[k][2]),
                twist: wn1[k][3],
            };
        }
        table
    }

    /// Force of every wall-contact slot on its wall (`i * wall_slots + slot`), as the walls
    /// pass left it for the reduction.
    pub fn slot_wall_forces(&self) -> Vec<DVec3> {
        self.read_vec3("wall_force", self.sizes.monomers * self.sizes.wall_slots)
    }

    /// Walls with their current points as the device holds them.
    pub fn current_walls(&self) -> Vec<Wall> {
        let gpu: Vec<GpuWall> = self.read("walls", self.walls.len());
        self.walls
            .iter()
            .zip(gpu)
            .map(|(w, g)| Wall {
                point: DVec3::new(g.point[0], g.point[1], g.point[2]),
                ..w.clone()
            })
            .collect()
    }

    /// Per-monomer energy tallies (the seven dissipation channels, then the wall work) since
    /// the small block was last read.
    pub fn monomer_tallies(&self) -> Vec<[f64; layout::TALLY_STRIDE]> {
        self.read("tally", self.sizes.monomers)
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

    /// Energy report of the current state (a full readback).
    pub fn energy(&self) -> EnergyReport {
        self.snapshot().energy()
    }

    /// Advances `steps` steps and returns each wall's force averaged over them (from the
    /// per-batch sums of the small block).
    pub fn run_mean_wall_force(&mut self, steps: u64) -> Result<Vec<DVec3>, GpuError> {
        let mut sum = vec![DVec3::ZERO; self.walls.len()];
        let mut left = steps;
        while left > 0 {
            let batch = left.min(self.readback_every.max(1));
            self.run(batch)?;
            let d = &self.diagnostics;
            for (s, m) in sum.iter_mut().zip(&d.mean_wall_force) {
                *s += *m * d.mean_steps as f64;
            }
            left -= batch;
        }
        Ok(sum.into_iter().map(|s| s / steps.max(1) as f64).collect())
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
    fn time(&self) -> f64 {
        self.time
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
}

/// Maps `buffer` (MAP_READ), waits, and copies out its first `bytes` bytes; a failed device
/// is an error, not a panic.
fn map_read(ctx: &GpuContext, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
    let slice = buffer.slice(..bytes);
    let mapped = std::sync::Arc::new(std::sync::Mutex::new(None));
    let done = std::sync::Arc::clone(&mapped);
    slice.map_async(wgpu::MapMode::Read, move |r| {
        *done.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
    });
    let polled = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    let failed = |why: String| Err(GpuError::DeviceLost(ctx.failure().unwrap_or(why)));
    if let Err(e) = polled {
        return failed(e.to_string());
    }
    let result = mapped.lock().unwrap_or_else(|p| p.into_inner()).take();
    match result {
        Some(Ok(())) => {}
        Some(Err(e)) => return failed(format!("mapping a readback buffer: {e}")),
        None => return failed("a readback never completed".into()),
    }
    if let Some(why) = ctx.failure() {
        return Err(GpuError::DeviceLost(why));
    }
    let out = match slice.get_mapped_range() {
        Ok(view) => view.to_vec(),
        Err(e) => return failed(format!("reading a mapped buffer: {e}")),
    };
    buffer.unmap();
    Ok(out)
}
