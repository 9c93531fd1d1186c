//! Compression curves on both backends: the same RBD sample compressed by the same wall, rows
//! compared one by one.
//!
//! The issue asks for statistical parity (φ(P) within ±0.01 at every decade of P; the mean
//! wall force of a 1 cm/s segment within 2%), because a chaotic many-body run on another
//! backend would diverge step by step. In the exact float mode it does not diverge: the GPU's
//! trajectory equals the CPU's to the bit, so φ and the contact counts must be equal and the
//! pressures may differ only by the summation order of the wall forces (1e-9 relative here,
//! far inside the 2% the issue allows). In the relaxed mode the statistical bounds
//! apply.

mod gpu_support;

use dustdem::config::Config;
use dustdem::experiment::compression::{Compression, Engine, Event, Row};
use dustdem::gpu::context::context_for_tests;
use dustdem::gpu::engine::GpuEngine;
use dustdem::gpu::shader::FloatMode;

fn rows<E: Engine>(mut run: Compression<E>) -> Vec<Row> {
    let mut rows = Vec::new();
    run.run(&mut |event| {
        if let Event::Row(row) = event {
            rows.push(*row);
        }
        Ok(())
    })
    .unwrap();
    rows
}

fn both(text: &str) -> Option<(Vec<Row>, Vec<Row>, FloatMode)> {
    let config = Config::parse(text, "test").unwrap();
    let ctx = context_for_tests()?;
    let mode = ctx.float_mode;
    let cpu = rows(Compression::new(&config).unwrap());
    let gpu = rows(
        Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
            Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
        })
        .unwrap(),
    );
    Some((cpu, gpu, mode))
}

/// Largest |ΔP| relative to the largest |P| of the run.
fn pressure_difference(cpu: &[Row], gpu: &[Row]) -> f64 {
    let scale = cpu
        .iter()
        .filter(|r| r.p_top.is_finite())
        .map(|r| r.p_top.abs().max(r.p_bottom.abs()))
        .fold(0.0, f64::max);
    cpu.iter()
        .zip(gpu)
        .filter(|(a, _)| a.p_top.is_finite())
        .map(|(a, b)| {
            (a.p_top - b.p_top)
                .abs()
                .max((a.p_bottom - b.p_bottom).abs())
                / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_1_m_per_s_omni_compression_gives_the_same_curve() {
    let Some((cpu, gpu, mode)) = both(
        "[sample]\nmonomers = 300\nseed = 4\n[experiment]\nkind = \"omni\"\n\
         wall_speed_m_s = 1.0\nphi_stop = 0.3\naverage_steps = 200\n",
    ) else {
        return;
    };
    assert_eq!(cpu.len(), gpu.len());
    let dp = pressure_difference(&cpu, &gpu);
    let dphi = cpu
        .iter()
        .zip(&gpu)
        .map(|(a, b)| (a.phi - b.phi).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "{mode:?}: {} rows to φ = {:.3}, P_top up to {:.3e} Pa; max |Δφ| {dphi:e}, max |ΔP|/P {dp:e}",
        cpu.len(),
        cpu.last().unwrap().phi,
        cpu.iter().map(|r| r.p_top).fold(0.0, f64::max)
    );
    match mode {
        FloatMode::Exact => {
            assert_eq!(dphi, 0.0);
            assert!(dp <= 1e-9, "{dp:e}");
            for (a, b) in cpu.iter().zip(&gpu) {
                assert_eq!((a.contacts, a.wall_contacts), (b.contacts, b.wall_contacts));
            }
        }
        FloatMode::Relaxed => assert!(dphi <= 0.01),
    }
}

#[test]
fn a_1_cm_per_s_segment_gives_the_same_mean_wall_force() {
    // 6700 steps of 0.3 ns at 1 cm/s: 20 nm of wall travel.
    let Some((cpu, gpu, mode)) = both(
        "[sample]\nmonomers = 300\nseed = 4\n[experiment]\nkind = \"omni\"\n\
         wall_speed_m_s = 0.01\nmax_steps = 6700\naverage_steps = 6700\n",
    ) else {
        return;
    };
    let (a, b) = (cpu.last().unwrap(), gpu.last().unwrap());
    let travel = (cpu[0].wall_gap - a.wall_gap) * 1e7;
    let rel = (a.p_top - b.p_top).abs() / a.p_top.abs();
    eprintln!(
        "{mode:?}: wall travel {travel:.1} nm, mean top pressure cpu {:.9e} gpu {:.9e} Pa (rel {rel:.1e})",
        a.p_top, b.p_top
    );
    assert!(travel >= 20.0 - 1e-9);
    assert!(a.p_top != 0.0);
    let bound = if mode == FloatMode::Exact { 1e-9 } else { 0.02 };
    assert!(rel <= bound, "{rel:e}");
}
