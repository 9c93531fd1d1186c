//! Throughput of the CPU reference: particle-steps per second on RBD samples under
//! omnidirectional compression at 1 m/s, for N = 10³, 10⁴, 10⁵ (override with
//! `DUSTDEM_BENCH_SIZES=1000,10000`), with the time per pass. Prints a Markdown table.
//!
//! Run: `cargo bench --bench cpu_throughput`. `dustdem bench` measures the same compression
//! with rounds, thread counts, the GPU engine and LAMMPS beside it.

use dustdem::backend::cpu::PASS_NAMES;
use dustdem::bench::{benchmark_config, benchmark_engine};
use std::time::Instant;

fn main() {
    let sizes: Vec<usize> = std::env::var("DUSTDEM_BENCH_SIZES")
        .ok()
        .map(|s| {
            s.split(',')
                .map(|x| x.trim().parse().expect("sizes are integers"))
                .collect()
        })
        .unwrap_or_else(|| vec![1_000, 10_000, 100_000]);
    println!(
        "| N | steps | contacts/monomer | particle-steps/s | µs/step | {} |",
        PASS_NAMES.join(" % | ") + " %"
    );
    println!("|---|---|---|---|---|{}", "---|".repeat(PASS_NAMES.len()));
    for n in sizes {
        // The compression `dustdem bench` measures (src/bench).
        let config = benchmark_config(n).expect("valid benchmark config");
        let (mut engine, _, _) = benchmark_engine(&config).expect("setup");
        // Warm up past the first contact changes, then measure.
        let steps = (2e8 / n as f64).clamp(200.0, 20_000.0) as u64;
        engine.run(steps / 10).expect("warm-up");
        engine.pass_seconds = [0.0; 5];
        let clock = Instant::now();
        engine.run(steps).expect("run");
        let seconds = clock.elapsed().as_secs_f64();
        let coordination = 2.0 * engine.contacts.pair_contact_count() as f64 / n as f64;
        let total: f64 = engine.pass_seconds.iter().sum();
        let shares: Vec<String> = engine
            .pass_seconds
            .iter()
            .map(|s| format!("{:.0}", 100.0 * s / total))
            .collect();
        println!(
            "| {n} | {steps} | {coordination:.2} | {:.3e} | {:.1} | {} |",
            n as f64 * steps as f64 / seconds,
            1e6 * seconds / steps as f64,
            shares.join(" | ")
        );
    }
}
