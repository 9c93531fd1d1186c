//! Throughput of the GPU engine (lavapipe here, whatever adapter the machine has elsewhere)
//! next to the CPU reference: particle-steps per second on RBD samples under omnidirectional
//! compression at 1 m/s, for N = 10³, 10⁴ (override with `DUSTDEM_BENCH_SIZES=1000,10000,100000`;
//! the step count with `DUSTDEM_BENCH_STEPS`),
//! with the time per pass of the GPU step. Prints a Markdown table.
//!
//! `DUSTDEM_BENCH_ROUNDS=R` (default 1) times R rounds, each a run of the CPU reference and one
//! of the GPU engine back to back (both engines carry on from where they stopped), and reports
//! the median of each rate and the median and range of the per-round ratios: on a shared host
//! the two backends of one round meet the same load.
//!
//! Run: `cargo bench --bench gpu_throughput`. Per-pass times come from timestamps written
//! before and after every dispatch of 20 ordinary steps (where the device has timestamp queries
//! inside passes); they leave out the gaps between dispatches, so they add up to less than the
//! step.

use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::{GpuContext, Requirements};
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::config::Config;
use dustdem::experiment::compression::Compression;
use std::time::Instant;

/// The compression `dustdem bench` measures (src/bench).
fn config(n: usize) -> Config {
    dustdem::bench::benchmark_config(n).expect("valid benchmark config")
}

/// `DUSTDEM_FLOAT_MODE=relaxed` (or `exact`) measures that mode instead of the device's best.
fn float_mode_override() -> Option<FloatMode> {
    match std::env::var("DUSTDEM_FLOAT_MODE").ok()?.as_str() {
        "relaxed" => Some(FloatMode::Relaxed),
        "exact" => Some(FloatMode::Exact),
        other => panic!("DUSTDEM_FLOAT_MODE={other}: expected relaxed or exact"),
    }
}

fn main() {
    let sizes: Vec<usize> = std::env::var("DUSTDEM_BENCH_SIZES")
        .ok()
        .map(|s| {
            s.split(',')
                .map(|x| x.trim().parse().expect("sizes are integers"))
                .collect()
        })
        .unwrap_or_else(|| vec![1_000, 10_000]);
    let probe = GpuContext::new(&Requirements::default()).expect("a GPU adapter with f64");
    println!(
        "adapter: {} ({:?} float mode)",
        probe.summary().name,
        float_mode_override().unwrap_or(probe.float_mode)
    );
    drop(probe);
    let names: Vec<&str> = GpuEngine::passes().iter().map(|k| k.entry()).collect();
    let rounds: usize = std::env::var("DUSTDEM_BENCH_ROUNDS")
        .map(|s| s.parse().expect("DUSTDEM_BENCH_ROUNDS is an integer"))
        .unwrap_or(1)
        .max(1);
    println!(
        "| N | steps | rounds | GPU particle-steps/s | CPU particle-steps/s | GPU/CPU | GPU/CPU range | GPU µs/step | {} |",
        names.join(" µs | ") + " µs"
    );
    println!(
        "|---|---|---|---|---|---|---|---|{}",
        "---|".repeat(names.len())
    );
    for n in sizes {
        let steps = match std::env::var("DUSTDEM_BENCH_STEPS") {
            Ok(s) => s.parse().expect("DUSTDEM_BENCH_STEPS is an integer"),
            Err(_) => (1e7 / n as f64).clamp(200.0, 5_000.0) as u64,
        };
        let cfg = config(n);

        let mut cpu = Compression::with_engine(&cfg, CpuEngine::new).expect("setup");
        cpu.engine.run(steps / 10).expect("warm-up");

        let mut ctx = GpuContext::new(&Requirements::default()).expect("adapter");
        if let Some(mode) = float_mode_override() {
            ctx.float_mode = mode;
        }
        let mut gpu = Compression::with_engine(&cfg, |law, dt, m, w, ps, ws| {
            Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
        })
        .expect("setup");
        gpu.engine.run(steps / 10).expect("warm-up");
        let particle_steps = n as f64 * steps as f64;
        let (mut cpu_rates, mut gpu_rates, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..rounds {
            let clock = Instant::now();
            cpu.engine.run(steps).expect("run");
            let cpu_rate = particle_steps / clock.elapsed().as_secs_f64();
            let clock = Instant::now();
            gpu.engine.run(steps).expect("run");
            let gpu_rate = particle_steps / clock.elapsed().as_secs_f64();
            cpu_rates.push(cpu_rate);
            gpu_rates.push(gpu_rate);
            ratios.push(gpu_rate / cpu_rate);
        }
        let (cpu_rate, gpu_rate) = (median(&cpu_rates), median(&gpu_rates));
        let passes: Vec<String> = match gpu.engine.profile_passes(20).expect("profiled steps") {
            Some(times) => times
                .iter()
                .map(|(_, s)| format!("{:.0}", s * 1e6))
                .collect(),
            None => vec!["–".into(); names.len()],
        };
        let low = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let high = ratios.iter().copied().fold(0.0, f64::max);
        println!(
            "| {n} | {steps} | {rounds} | {gpu_rate:.3e} | {cpu_rate:.3e} | {:.2} | {low:.2}–{high:.2} | {:.0} | {} |",
            median(&ratios),
            1e6 * n as f64 / gpu_rate,
            passes.join(" | ")
        );
    }
}

/// Median (the mean of the middle two for an even count).
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[mid]
    } else {
        0.5 * (sorted[mid - 1] + sorted[mid])
    }
}
