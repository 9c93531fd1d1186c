//! A measurement row on the device: the row kernels (shaders/passes/rows.wgsl) reduce the
//! energies, the extent of the centres, the solid volume per slab and the covered pixels of
//! the projected area, and the host reads back those few numbers, never the state. One
//! submission and one small read for the energies and a profile; a uni run's area takes a
//! second, since the raster's grid is sized by the extent the first one found.

use super::{groups, GpuEngine, GpuError};
use crate::backend::gpu::interface::{Binding, Kernel};
use crate::backend::gpu::layout::{self, MONOMER_GROUP, REDUCE_BLOCK, ROW_SUMS};
use crate::state::rows::{sphere_volume, Raster, RowMeasures, RowRequest};
use crate::state::EnergyReport;

impl GpuEngine {
    /// The row measures of the current state, reduced on the device in the order of
    /// `state::rows` (the same bits as the CPU's in the exact float mode).
    pub fn row_measures(&mut self, request: &RowRequest) -> Result<RowMeasures, GpuError> {
        let n = self.sizes.monomers;
        let r = self.law.radius;
        let blocks = n.div_ceil(REDUCE_BLOCK);
        let slabs = request.slabs.filter(|s| s.count > 0 && n > 0);
        let count = slabs.map_or(0, |s| s.count);
        // Solid volume per slab, then per (slab, block).
        let profile_bytes =
            self.device_len(Binding::RowProfileData, (count * (blocks + 1) * 8) as u64);
        self.ensure_scratch(Binding::RowProfileData, profile_bytes);
        let mut header = [0.0f64; layout::ROW_NY + 1];
        header[layout::ROW_MASS] = self.law.mass;
        header[layout::ROW_INERTIA] = self.law.moment_of_inertia;
        header[layout::ROW_SPHERE] = sphere_volume(r);
        if let Some(s) = slabs {
            header[layout::ROW_SLAB_BOTTOM] = s.bottom;
            header[layout::ROW_SLAB_THICKNESS] = s.thickness;
            header[layout::ROW_SLABS] = s.count as f64;
        }
        self.write_row_data(0, &header);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.dispatch_row(&mut pass, Kernel::RowSums, groups(n));
            self.dispatch_row(&mut pass, Kernel::RowSumsFinal, 1);
            if count > 0 {
                let cells = (count * blocks).div_ceil(MONOMER_GROUP) as u32;
                self.dispatch_row(
                    &mut pass,
                    Kernel::RowProfile,
                    cells.min(self.work_groups_max),
                );
                self.dispatch_row(&mut pass, Kernel::RowProfileFinal, groups(count));
            }
        }
        let sums_bytes = self.device_len(Binding::RowData, (ROW_SUMS * 8) as u64);
        let slab_bytes = self.device_len(Binding::RowProfileData, (count * 8) as u64);
        encoder.copy_buffer_to_buffer(
            self.buffers.get(Binding::RowData),
            self.device_offset(Binding::RowData, (layout::ROW_RESULTS * 8) as u64),
            &self.row_readback,
            0,
            sums_bytes,
        );
        if count > 0 {
            encoder.copy_buffer_to_buffer(
                self.buffers.get(Binding::RowProfileData),
                0,
                &self.row_readback,
                sums_bytes,
                slab_bytes,
            );
        }
        self.ctx.queue.submit([encoder.finish()]);
        let raw = self.map_counted(&self.row_readback, sums_bytes + slab_bytes)?;
        let (sums, slabs) = raw.split_at(sums_bytes as usize);
        let sums: Vec<f64> =
            bytemuck::pod_collect_to_vec(&self.decoded(Binding::RowData, sums.to_vec()));
        let slab_volumes: Vec<f64> =
            bytemuck::pod_collect_to_vec(&self.decoded(Binding::RowProfileData, slabs.to_vec()));
        let projected_area = if request.projected_area {
            Some(if n == 0 {
                0.0
            } else {
                self.covered_area(Raster::new([sums[4], sums[5]], [sums[6], sums[7]], r))?
            })
        } else {
            None
        };
        let d = &self.diagnostics;
        Ok(RowMeasures {
            energy: EnergyReport {
                kinetic: sums[0],
                rotational: sums[1],
                normal_potential: sums[2],
                tangential_potential: sums[3],
                dissipated: d.tally,
                wall_work: d.wall_work,
            },
            contacts: (d.pair_contacts, d.wall_contacts),
            slab_volumes: match request.slabs {
                Some(s) if count == 0 => vec![0.0; s.count],
                Some(_) => slab_volumes,
                None => Vec::new(),
            },
            projected_area,
        })
    }

    /// Area of the pixels of `grid` the monomers' disks cover (the raster and its count on the
    /// device; four bytes come back).
    fn covered_area(&mut self, grid: Raster) -> Result<f64, GpuError> {
        let words = grid.words();
        let bits_bytes = ((1 + words) * 4) as u64;
        self.ensure_scratch(Binding::RowBits, bits_bytes);
        self.write_row_data(
            layout::ROW_X0,
            &[grid.x0, grid.y0, grid.pixel, grid.nx as f64, grid.ny as f64],
        );
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(
            self.buffers.get(Binding::RowBits),
            0,
            Some(bits_bytes.next_multiple_of(4)),
        );
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.dispatch_row(&mut pass, Kernel::RowRaster, groups(self.sizes.monomers));
            let word_groups = groups(words).min(self.work_groups_max);
            self.dispatch_row(&mut pass, Kernel::RowArea, word_groups);
        }
        encoder.copy_buffer_to_buffer(
            self.buffers.get(Binding::RowBits),
            0,
            &self.row_readback,
            0,
            4,
        );
        self.ctx.queue.submit([encoder.finish()]);
        let raw = self.map_counted(&self.row_readback, 4)?;
        let pixels = u32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]]);
        Ok(f64::from(pixels) * grid.pixel * grid.pixel)
    }

    /// The whole `row_data` binding (parameters, results, then the per-block sums of
    /// `row_sums`), for the tests that hold the blocks to their twin.
    pub fn row_data(&self) -> Vec<f64> {
        let len = layout::ROW_PARTIALS + ROW_SUMS * self.sizes.monomers.div_ceil(REDUCE_BLOCK);
        self.read(Binding::RowData, len)
    }

    fn write_row_data(&self, at: usize, values: &[f64]) {
        self.write_at(Binding::RowData, (at * 8) as u64, values);
    }

    fn dispatch_row(&self, pass: &mut wgpu::ComputePass<'_>, kernel: Kernel, groups: u32) {
        pass.set_pipeline(self.kernels.pipeline(kernel));
        pass.set_bind_group(0, &self.bind_groups[kernel as usize], &[]);
        pass.dispatch_workgroups(groups, 1, 1);
    }

    /// Grows scratch binding `name` to hold `bytes` (doubling, so a slowly growing extent
    /// reallocates rarely) and the readback buffer to hold what the rows read; the bind
    /// groups are rebuilt around the new buffer.
    fn ensure_scratch(&mut self, binding: Binding, bytes: u64) {
        if self.buffers.get(binding).size() < bytes {
            let grown = bytes.max(2 * self.buffers.get(binding).size());
            self.buffers.grow(&self.ctx.device, binding, grown);
            self.bind_groups = self.kernels.bind_groups(&self.ctx.device, &self.buffers);
        }
        // The profile's results come back after the sums (device bytes, at most the host's).
        let readback = (ROW_SUMS * 8) as u64 + self.buffers.get(Binding::RowProfileData).size();
        if self.row_readback.size() < readback {
            self.row_readback = row_readback_buffer(&self.ctx.device, readback);
        }
    }
}

/// The staging buffer the row measures are read through.
pub(super) fn row_readback_buffer(device: &wgpu::Device, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("row readback"),
        size: bytes.max(64).next_multiple_of(8),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
