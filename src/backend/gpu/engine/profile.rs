//! Per-pass timings: ordinary steps with a timestamp around every dispatch.

use super::{GpuEngine, GpuError};
use crate::backend::gpu::kernels::Kernel;

impl GpuEngine {
    /// Advances `steps` ordinary steps (one submission, at most 227) with a timestamp before
    /// and after every dispatch, and returns the mean seconds per step of each kernel of
    /// [`GpuEngine::passes`] (`integrate_kick` and `reduce_walls_final` run once per
    /// submission); `None` where the device lacks timestamp queries inside passes.
    pub fn profile_passes(&mut self, steps: u32) -> Result<Option<Vec<(Kernel, f64)>>, GpuError> {
        let device = &self.ctx.device;
        if !device
            .features()
            .contains(crate::backend::gpu::context::TIMING_FEATURES)
        {
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
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&self.map_counted(&staging, bytes)?);
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
}
