//! Reading back from the device: the small block after every submission (flags, wall forces,
//! contact counts, tally) with its overflow flags turned into errors, and the full state on
//! request.

use super::{Diagnostics, GpuEngine, GpuError};
use crate::backend::gpu::buffers::{PAIR_N1, PAIR_N2};
use crate::backend::gpu::context::GpuContext;
use crate::backend::gpu::interface::{Binding, Kernel};
use crate::backend::gpu::layout::SLOT_CHUNKS;
use crate::backend::gpu::layout::{self, GpuMonomerAux, GpuWall};
use crate::backend::gpu::shader::Precision;
use crate::engine::EngineError;
use crate::mixed::split::SplitPosition;
use crate::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
use glam::{DVec3, IVec3};

impl GpuEngine {
    pub(super) fn clear_wall_force_sum(&self) {
        let zeros = [0.0f64; layout::DIAG_SIZE - layout::DIAG_WALL_FORCE_SUM];
        self.write_at(
            Binding::Diag,
            (layout::DIAG_WALL_FORCE_SUM * 8) as u64,
            &zeros,
        );
        self.write_at(Binding::Diag, (layout::DIAG_STEPS * 8) as u64, &[0.0f64]);
    }

    /// Reduces the tallies and counts, reads flags and the diagnostics block, and turns a raised
    /// flag into its error.
    pub(super) fn read_small(&mut self) -> Result<(), GpuError> {
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.encode(&mut pass, &[Kernel::ReduceDiagnostics]);
        }
        let flag_bytes = (layout::FLAG_COUNT * 4) as u64;
        let flags_at = 0;
        let diag_at = flag_bytes.next_multiple_of(8);
        let diag_bytes = self.device_len(Binding::Diag, (layout::DIAG_SIZE * 8) as u64);
        encoder.copy_buffer_to_buffer(
            self.buffers.get(Binding::Flags),
            0,
            &self.buffers.small_readback,
            flags_at,
            flag_bytes,
        );
        encoder.copy_buffer_to_buffer(
            self.buffers.get(Binding::Diag),
            0,
            &self.buffers.small_readback,
            diag_at,
            diag_bytes,
        );
        // Counted from here on: the totals live on the host.
        encoder.clear_buffer(self.buffers.get(Binding::Tally), 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        let bytes = self.map_counted(&self.buffers.small_readback, diag_at + diag_bytes)?;
        let flags: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes[..flag_bytes as usize]);
        let diag = self.decoded(Binding::Diag, bytes[diag_at as usize..].to_vec());
        let diag: Vec<f64> = bytemuck::pod_collect_to_vec(&diag);
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

    /// [`map_read`], counted in [`GpuEngine::bytes_read_back`].
    pub(super) fn map_counted(
        &self,
        buffer: &wgpu::Buffer,
        bytes: u64,
    ) -> Result<Vec<u8>, GpuError> {
        self.read_back
            .fetch_add(bytes, std::sync::atomic::Ordering::Relaxed);
        map_read(&self.ctx, buffer, bytes)
    }

    /// A per-slot vector array, gathered from its chunk bindings.
    fn read_slots(&self, chunks: [Binding; SLOT_CHUNKS], count: usize) -> Vec<[f64; 4]> {
        let chunk = self.sizes.slot_chunk();
        let mut out = Vec::with_capacity(count);
        for c in 0..layout::SLOT_CHUNKS {
            let part = count.saturating_sub(c * chunk).min(chunk);
            if part == 0 {
                break;
            }
            out.extend(self.read::<[f64; 4]>(chunks[c], part));
        }
        out
    }

    fn read_vec3(&self, binding: Binding, count: usize) -> Vec<DVec3> {
        self.read::<[f64; 4]>(binding, count)
            .into_iter()
            .map(|v| DVec3::new(v[0], v[1], v[2]))
            .collect()
    }

    /// Positions at the current time (a full-array readback).
    pub fn positions(&self) -> Vec<DVec3> {
        let n = self.sizes.monomers;
        match self.precision {
            Precision::Exact => self.read_vec3(Binding::Position, n),
            // Split centres (shaders/mixed_engine/positions.wgsl): voxel, offset, low part.
            Precision::Mixed => {
                let voxel: Vec<[i32; 4]> = self.read(Binding::PositionVoxel, n);
                let offset = self.read_vec3(Binding::Position, n);
                let lo = self.read_vec3(Binding::PositionLo, n);
                (0..n)
                    .map(|i| {
                        SplitPosition {
                            voxel: IVec3::from_slice(&voxel[i][..3]),
                            offset: offset[i].as_vec3(),
                            offset_lo: lo[i].as_vec3(),
                        }
                        .to_f64()
                    })
                    .collect()
            }
        }
    }

    /// The monomers as the CPU engine stores them.
    pub fn monomers(&self) -> Monomers {
        let n = self.sizes.monomers;
        let aux: Vec<GpuMonomerAux> = self.read(Binding::Aux, n);
        Monomers {
            position: self.positions(),
            velocity: self.read_vec3(Binding::Velocity, n),
            angular_velocity: self.read_vec3(Binding::AngularVelocity, n),
            force: self.read_vec3(Binding::Force, n),
            torque: self.read_vec3(Binding::Torque, n),
            damping_force: self.read_vec3(Binding::DampingForce, n),
            inverse_mass_scale: aux.iter().map(|a| a.inverse_mass_scale).collect(),
            inverse_inertia_scale: aux.iter().map(|a| a.inverse_inertia_scale).collect(),
            id: self.ids.clone(),
        }
    }

    /// The contact history as the CPU engine stores it (slots beyond the counts are whatever
    /// the device left there).
    pub fn contacts(&self) -> ContactTable {
        let n = self.sizes.monomers;
        let (ps, ws) = (self.sizes.pair_slots, self.sizes.wall_slots);
        let mut table = ContactTable::new(n, ps, ws);
        let n1 = self.read_slots(PAIR_N1, n * ps);
        let n2 = self.read_slots(PAIR_N2, n * ps);
        let partner: Vec<u32> = self.read(Binding::PairPartner, n * ps);
        table.pair_count = self.read(Binding::PairCount, n);
        for (k, c) in table.pair.iter_mut().enumerate() {
            *c = PairContact {
                partner: partner[k],
                n1: DVec3::new(n1[k][0], n1[k][1], n1[k][2]),
                n2: DVec3::new(n2[k][0], n2[k][1], n2[k][2]),
                twist: n1[k][3],
            };
        }
        let wn1: Vec<[f64; 4]> = self.read(Binding::WallN1, n * ws);
        let anchor: Vec<[f64; 4]> = self.read(Binding::WallAnchor, n * ws);
        let wall_id: Vec<u32> = self.read(Binding::WallId, n * ws);
        table.wall_count = self.read(Binding::WallCount, n);
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
        self.read_vec3(
            Binding::WallForce,
            self.sizes.monomers * self.sizes.wall_slots,
        )
    }

    /// Walls with their current points as the device holds them.
    pub fn current_walls(&self) -> Vec<Wall> {
        let gpu: Vec<GpuWall> = self.read(Binding::Walls, self.walls.len());
        self.walls
            .iter()
            .zip(gpu)
            .map(|(w, g)| {
                let point = DVec3::from_slice(&g.point[..3]);
                Wall {
                    point: match self.precision {
                        Precision::Exact => point,
                        // The double-f32 point (shaders/mixed_engine/positions.wgsl).
                        Precision::Mixed => point + DVec3::from_slice(&g.point_lo[..3]),
                    },
                    ..w.clone()
                }
            })
            .collect()
    }

    /// The first `count` values of `binding` as the host lays them out: what a pass left on the
    /// device, for the tests that hold each pass to its CPU twin.
    pub fn read_binding<T: bytemuck::Pod>(&self, binding: Binding, count: usize) -> Vec<T> {
        self.read(binding, count)
    }

    /// Per-monomer energy tallies (the seven dissipation channels, then the wall work) since
    /// the small block was last read.
    pub fn monomer_tallies(&self) -> Vec<[f64; layout::TALLY_STRIDE]> {
        self.read(Binding::Tally, self.sizes.monomers)
    }
}

/// Maps `buffer` (MAP_READ), waits, and copies out its first `bytes` bytes; a failed device
/// is an error, not a panic.
pub(super) fn map_read(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<u8>, GpuError> {
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
