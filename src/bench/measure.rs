//! The engines a round measures ("sides"), how many steps each gets, and one timed run of each.
//!
//! Step counts come from the side's own speed: a probe of doubling runs until one takes a
//! tenth of the target, then steps = target seconds / seconds per step. So every measurement
//! takes about the same time whatever N and engine, and no side runs for hours.

use super::options::{Options, Threads, LAMMPS_RANKS};
use crate::backend::cpu::{CpuEngine, PASS_NAMES};
use crate::backend::gpu::context::{GpuContext, Requirements, ShaderF64};
use crate::backend::gpu::engine::GpuEngine;
use crate::backend::gpu::shader::Precision;
use crate::state::State;
use std::time::Instant;

/// Fewest and most steps of a measurement.
pub const STEPS_RANGE: (u64, u64) = (10, 100_000_000);
/// LAMMPS's timing sections, in the order its log prints them.
pub const LAMMPS_SECTIONS: [&str; 6] = ["Pair", "Neigh", "Comm", "Output", "Modify", "Other"];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SideKind {
    Cpu(Threads),
    /// The CPU engine with the monomers in the sample's order (no space-filling order).
    CpuSampleOrder(Threads),
    /// The CPU engine not booking the corrections' dissipation (`[output] tally_corrections
    /// = false`).
    CpuUntallied(Threads),
    Gpu(Precision),
    Lammps {
        ranks: usize,
    },
}

/// One engine configuration a round measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Side {
    pub kind: SideKind,
    /// Column prefix in bench.csv (`cpu_t1`, `cpu_all`, `gpu`, `lammps_r2`).
    pub key: String,
    /// Column heading in bench.md.
    pub label: String,
}

impl SideKind {
    /// Whether this side is the CPU engine (any of its variants).
    pub fn is_cpu(self) -> bool {
        matches!(
            self,
            SideKind::Cpu(_) | SideKind::CpuSampleOrder(_) | SideKind::CpuUntallied(_)
        )
    }
}

impl Side {
    /// The pass (or section) names this side reports times for.
    pub fn pass_names(&self) -> Vec<String> {
        match self.kind {
            SideKind::Cpu(_) | SideKind::CpuSampleOrder(_) | SideKind::CpuUntallied(_) => {
                PASS_NAMES.iter().map(|s| s.to_string()).collect()
            }
            SideKind::Gpu(_) => GpuEngine::passes()
                .iter()
                .map(|k| k.entry().to_string())
                .collect(),
            SideKind::Lammps { .. } => LAMMPS_SECTIONS.iter().map(|s| s.to_string()).collect(),
        }
    }
}

/// The sides of a round, in the order a round runs them: CPU thread counts, GPU, LAMMPS ranks.
pub fn sides(options: &Options) -> Vec<Side> {
    let mut sides = Vec::new();
    for &t in &options.threads {
        let (key, label) = match t {
            Threads::Count(1) => ("cpu_t1".to_string(), "cpu, 1 thread".to_string()),
            Threads::Count(t) => (format!("cpu_t{t}"), format!("cpu, {t} threads")),
            Threads::All => (
                "cpu_all".to_string(),
                format!("cpu, all {} threads", t.resolve()),
            ),
        };
        sides.push(Side {
            kind: SideKind::Cpu(t),
            key,
            label,
        });
    }
    if options.sample_order && !options.threads.is_empty() {
        sides.push(Side {
            kind: SideKind::CpuSampleOrder(Threads::All),
            key: "cpu_all_sample_order".into(),
            label: format!("cpu, all {} threads, sample order", Threads::All.resolve()),
        });
    }
    if options.untallied && !options.threads.is_empty() {
        sides.push(Side {
            kind: SideKind::CpuUntallied(Threads::All),
            key: "cpu_all_untallied".into(),
            label: format!(
                "cpu, all {} threads, corrections untallied",
                Threads::All.resolve()
            ),
        });
    }
    for &precision in &options.gpu {
        let (key, label) = match precision {
            Precision::Exact => ("gpu".into(), "gpu".into()),
            Precision::Mixed => ("gpu_mixed".into(), "gpu, mixed precision".into()),
        };
        sides.push(Side {
            kind: SideKind::Gpu(precision),
            key,
            label,
        });
    }
    if options.lammps {
        for ranks in LAMMPS_RANKS {
            sides.push(Side {
                kind: SideKind::Lammps { ranks },
                key: format!("lammps_r{ranks}"),
                label: format!("LAMMPS, {ranks} rank{}", if ranks == 1 { "" } else { "s" }),
            });
        }
    }
    sides
}

/// Steps for a measurement of `seconds` at `per_step` seconds per step.
pub fn steps_for(seconds: f64, per_step: f64) -> u64 {
    let steps = (seconds / per_step.max(1e-12)).round();
    (steps as u64).clamp(STEPS_RANGE.0, STEPS_RANGE.1)
}

/// Runs `run(k)` (k steps, returns the seconds they took) for k = 1, 2, 4, … until one call
/// takes `at_least` seconds or `budget` steps have run; returns (all steps run, seconds per
/// step of the last call).
pub fn probe(
    mut run: impl FnMut(u64) -> Result<f64, String>,
    at_least: f64,
    budget: u64,
) -> Result<(u64, f64), String> {
    let (mut k, mut total) = (1u64, 0u64);
    loop {
        let seconds = run(k)?;
        total += k;
        if seconds >= at_least || k >= STEPS_RANGE.1 || total >= budget {
            return Ok((total, seconds / k as f64));
        }
        // Aim straight at the target once a call is long enough to time.
        k = if seconds > 0.01 {
            ((at_least / seconds * k as f64).ceil() as u64).max(k + 1)
        } else {
            2 * k
        }
        .min(budget.saturating_sub(total).max(1));
    }
}

/// Runs `steps` steps of `engine` on `threads` threads; returns the seconds they took.
///
/// The thread count is set only by the pool the engine runs in: the engine's parallel passes
/// use whatever pool they are called from.
pub fn time_cpu(
    pool: &rayon::ThreadPool,
    engine: &mut CpuEngine,
    steps: u64,
) -> Result<f64, String> {
    let clock = Instant::now();
    pool.install(|| engine.run(steps))
        .map_err(|e| e.to_string())?;
    Ok(clock.elapsed().as_secs_f64())
}

/// The device requirements of a GPU side: f64 for the exact precision, refused for the mixed
/// one (so it runs at f32 even where the adapter has f64).
pub fn gpu_requirements(precision: Precision) -> Requirements {
    let shader_f64 = match precision {
        Precision::Exact => ShaderF64::Required,
        Precision::Mixed => ShaderF64::Refused,
    };
    Requirements {
        shader_f64,
        ..Requirements::default()
    }
}

/// A GPU engine at `precision` continuing from `state` on a fresh device context.
pub fn gpu_engine(state: &State, precision: Precision) -> Result<GpuEngine, String> {
    let ctx = GpuContext::new(&gpu_requirements(precision)).map_err(|e| e.to_string())?;
    GpuEngine::resume(ctx, state).map_err(|e| e.to_string())
}

/// Runs `steps` steps of `engine`; returns the seconds they took (each submission ends with a
/// read of the small block, so the device has finished).
pub fn time_gpu(engine: &mut GpuEngine, steps: u64) -> Result<f64, String> {
    let clock = Instant::now();
    engine.run(steps).map_err(|e| e.to_string())?;
    Ok(clock.elapsed().as_secs_f64())
}

/// Adds one round's pass times (seconds over `steps` steps) per step to `sum`.
pub fn add_passes(sum: &mut Vec<f64>, seconds: &[f64], steps: u64) {
    if sum.len() != seconds.len() {
        *sum = vec![0.0; seconds.len()];
    }
    for (m, s) in sum.iter_mut().zip(seconds) {
        *m += s / steps as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_stop_once_a_call_is_long_enough() {
        let mut calls = Vec::new();
        let (total, per_step) = probe(
            |k| {
                calls.push(k);
                Ok(k as f64 * 1e-3)
            },
            0.1,
            u64::MAX,
        )
        .unwrap();
        assert_eq!(*calls.last().unwrap(), 100);
        assert_eq!(total, calls.iter().sum::<u64>());
        assert!((per_step - 1e-3).abs() < 1e-15);
        assert_eq!(steps_for(20.0, 1e-3), 20_000);
        assert_eq!(steps_for(20.0, 100.0), STEPS_RANGE.0);
    }

    #[test]
    fn probes_stop_at_their_budget() {
        let mut calls = Vec::new();
        let (total, _) = probe(
            |k| {
                calls.push(k);
                Ok(k as f64 * 1e-9)
            },
            0.1,
            10,
        )
        .unwrap();
        assert_eq!(calls, [1, 2, 4, 3]);
        assert_eq!(total, 10);
    }
}
