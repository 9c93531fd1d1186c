//! The step script: the dispatches of one step in order, how a submission of several steps
//! encodes them, running steps and the host's side of each submission.

use super::{groups, GpuEngine, GpuError};
use crate::backend::gpu::interface::{Binding, Kernel};
use crate::state::simulated_time;
use glam::DVec3;

impl GpuEngine {
    /// The dispatches of one step, in order: the step script both engines run.
    pub const STEP: [Kernel; 10] = crate::backend::script::STEP;

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

    pub(super) fn encode(&self, pass: &mut wgpu::ComputePass<'_>, kernels: &[Kernel]) {
        let n = self.sizes.monomers;
        for &k in kernels {
            pass.set_pipeline(self.kernels.pipeline(k));
            pass.set_bind_group(0, &self.bind_groups[k as usize], &[]);
            if let Some(offset) = k.indirect_offset() {
                // Sized on the device by the scan that filled the list.
                pass.dispatch_workgroups_indirect(self.buffers.get(Binding::WorkArgs), offset);
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
    pub(super) fn advanced(&mut self, steps: u64) -> Result<(), GpuError> {
        // The device moves the walls the same way, so these points equal its own.
        for _ in 0..steps {
            for w in &mut self.walls {
                w.point += w.velocity * self.dt;
            }
        }
        self.step += steps;
        self.time = simulated_time(self.step, self.dt);
        self.read_small()?;
        self.clear_wall_force_sum();
        Ok(())
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
