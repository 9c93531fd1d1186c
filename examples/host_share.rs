//! How much of a GPU run's time the host spends outside the device's work, per step and per
//! row: the main thread's time on a CPU (`/proc/thread-self/schedstat`: while it waits for the
//! device it sleeps) against the wall-clock time, for the steps of a row
//! (`run_mean_wall_force`, one submission of 100 steps and the small block) and for the row's
//! measures (energies only as an omni row reads them; with the projected area as a uni row;
//! with a profile). On lavapipe the device's work runs in the driver's threads, so the main
//! thread's CPU time is the host's share.
//!
//! Run: `cargo run --release --example host_share` (`DUSTDEM_N`, default 100000;
//! `DUSTDEM_ROWS`, default 5).

use dustdem::backend::gpu::context::{GpuContext, Requirements};
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::config::Config;
use dustdem::engine::Engine;
use dustdem::experiment::compression::Compression;
use dustdem::state::rows::{RowRequest, Slabs};
use std::time::Instant;

/// Nanoseconds this thread has run on a CPU.
fn thread_cpu_ns() -> u64 {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").expect("schedstat");
    text.split_whitespace().next().unwrap().parse().unwrap()
}

/// (wall seconds, this thread's CPU seconds) of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let (t0, c0) = (Instant::now(), thread_cpu_ns());
    let out = f();
    let cpu = (thread_cpu_ns() - c0) as f64 * 1e-9;
    (out, t0.elapsed().as_secs_f64(), cpu)
}

fn main() {
    let n: usize = std::env::var("DUSTDEM_N").map_or(100_000, |s| s.parse().unwrap());
    let rows: usize = std::env::var("DUSTDEM_ROWS").map_or(5, |s| s.parse().unwrap());
    let text = format!("[sample]\nmonomers = {n}\nseed = 1\n[experiment]\nkind = \"omni\"\n");
    let config = Config::parse(&text, "host_share").unwrap();
    let ctx = GpuContext::new(&Requirements::default()).expect("a GPU adapter with f64");
    println!(
        "adapter: {}",
        ctx.summary().to_string().lines().next().unwrap()
    );
    let (run, setup, _) = timed(|| {
        Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
            Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
        })
        .unwrap()
    });
    let mut engine = run.engine;
    println!("N = {n}: setup (sample and engine) {setup:.1} s");
    let r = engine.law().radius;
    let walls = engine.walls();
    let slabs = Slabs::between(walls[0].point.z, walls[1].point.z, 2.0 * r);
    let requests = [
        ("energies", RowRequest::default()),
        (
            "energies + area",
            RowRequest {
                slabs: None,
                projected_area: true,
            },
        ),
        (
            "energies + profile",
            RowRequest {
                slabs: Some(slabs),
                projected_area: false,
            },
        ),
    ];
    let (mut step_wall, mut step_cpu) = (0.0, 0.0);
    let mut row = vec![(0.0, 0.0); requests.len()];
    for _ in 0..rows {
        let (_, wall, cpu) = timed(|| engine.run_mean_wall_force(100).unwrap());
        step_wall += wall;
        step_cpu += cpu;
        for (k, (_, request)) in requests.iter().enumerate() {
            let (_, wall, cpu) = timed(|| engine.row_measures(request).unwrap());
            row[k].0 += wall;
            row[k].1 += cpu;
        }
    }
    // What a row cost before the row kernels: the energy report of the full state, read back
    // (and the positions again for a uni row's area).
    let before = engine.bytes_read_back();
    let (_, wall, cpu) = timed(|| (engine.energy(), Engine::positions(&engine).len()));
    println!(
        "full readback for the energy report and the positions: {:.1} ms, host {:.1} ms, {} bytes",
        wall * 1e3,
        cpu * 1e3,
        engine.bytes_read_back() - before
    );
    let steps = (rows * 100) as f64;
    println!(
        "steps: {:.2} ms per step, host {:.1} µs per step ({:.3} % of the step)",
        step_wall / steps * 1e3,
        step_cpu / steps * 1e6,
        100.0 * step_cpu / step_wall
    );
    for ((name, _), (wall, cpu)) in requests.iter().zip(&row) {
        println!(
            "row measures ({name}): {:.1} ms per row, host {:.2} ms ({:.2} % of the row \
             measures; {:.3} % of a row of 100 steps with them)",
            wall / rows as f64 * 1e3,
            cpu / rows as f64 * 1e3,
            100.0 * cpu / wall,
            100.0 * cpu / (wall + step_wall)
        );
    }
}
