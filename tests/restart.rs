//! Checkpoints: an interrupted and resumed run is the run that was never interrupted, on the
//! CPU reference and on the GPU engine (lavapipe in CI).

mod common;

use common::Scratch;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::binary::{Decoder, Encoder};
use dustdem::config::Config;
use dustdem::experiment::compression::Compression;
use dustdem::state::State;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn assert_same_state(a: &State, b: &State) {
    let (m, n) = (&a.monomers, &b.monomers);
    assert_eq!(a.step, b.step);
    assert_eq!(a.time.to_bits(), b.time.to_bits());
    // Bit-identical: compare the encodings, which hold every field a step reads.
    let (mut ea, mut eb) = (Encoder::default(), Encoder::default());
    a.encode(&mut ea);
    b.encode(&mut eb);
    assert_eq!(m.position, n.position);
    assert_eq!(a.tally, b.tally);
    assert!(ea.bytes == eb.bytes, "engine states differ");
}

#[test]
fn checkpoint_and_resume_continue_bit_for_bit() {
    let config = Config::parse(
        "[sample]\nmonomers = 300\nseed = 5\n[experiment]\nwall_speed_m_s = 3.0\n",
        "restart test",
    )
    .unwrap();
    let mut straight = Compression::with_engine(&config, CpuEngine::new).unwrap();
    straight.engine.run(6000).unwrap();

    let mut first = Compression::with_engine(&config, CpuEngine::new).unwrap();
    first.engine.run(3000).unwrap();
    let mut e = Encoder::default();
    first.encode_state(&mut e);
    drop(first);
    let mut resumed = Compression::decode_state(&config, &mut Decoder::new(&e.bytes))
        .unwrap()
        .map_engine(|state| Ok(CpuEngine::from_state(state)))
        .unwrap();
    resumed.engine.run(3000).unwrap();

    assert!(straight.engine.contacts.pair_contact_count() > 0);
    assert!(straight.engine.tally.total() > 0.0, "something happened");
    assert_same_state(&straight.engine, &resumed.engine);
}

#[test]
fn gpu_checkpoint_and_resume_continue_bit_for_bit() {
    let config = Config::parse(
        "[sample]\nmonomers = 300\nseed = 5\n[experiment]\nwall_speed_m_s = 3.0\n",
        "restart test",
    )
    .unwrap();
    let on_gpu = || {
        let ctx = context_for_tests()?;
        Some(
            Compression::with_engine(&config, |law, dt, m, w, ps, ws| {
                Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
            })
            .unwrap(),
        )
    };
    let Some(mut straight) = on_gpu() else {
        return;
    };
    straight.engine.run(1200).unwrap();

    let mut first = on_gpu().unwrap();
    first.engine.run(600).unwrap();
    let mut e = Encoder::default();
    first.encode_state(&mut e);
    drop(first);
    let decoded = Compression::decode_state(&config, &mut Decoder::new(&e.bytes)).unwrap();
    let ctx = context_for_tests().unwrap();
    let mut resumed = decoded
        .map_engine(|state| Ok(GpuEngine::resume(ctx, &state)?))
        .unwrap();
    resumed.engine.run(600).unwrap();

    let (a, b) = (straight.engine.snapshot(), resumed.engine.snapshot());
    assert!(a.contacts.pair_contact_count() > 0);
    assert!(a.tally.total() > 0.0, "something happened");
    assert_same_state(&a, &b);
    assert_eq!(straight.engine.wall_force(), resumed.engine.wall_force());
}

fn dustdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("restart-{name}"))
}

#[test]
fn a_cpu_run_killed_with_sigkill_resumes_to_the_same_curve() {
    killed_and_resumed("cpu");
}

#[test]
fn a_gpu_run_killed_with_sigkill_resumes_to_the_same_curve() {
    if context_for_tests().is_some() {
        killed_and_resumed("gpu");
    }
}

/// Runs a small compression straight, and again killed with SIGKILL after a checkpoint and
/// resumed, both on `backend`; the curve and profile files must be byte-identical.
fn killed_and_resumed(backend: &str) {
    let dir = scratch(&format!("kill-{backend}"));
    let config = dir.join("run.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 400\nseed = 2\n[experiment]\nwall_speed_m_s = 2.0\nphi_stop = 0.3\n\
         [output]\ncheckpoint_every_rows = 10\n",
    )
    .unwrap();
    let (straight, killed) = (dir.join("straight"), dir.join("killed"));
    let status = dustdem()
        .args([
            "run",
            config.to_str().unwrap(),
            "--out",
            straight.to_str().unwrap(),
            "--backend",
            backend,
            "--quiet",
        ])
        .status()
        .unwrap();
    assert!(status.success());

    let mut child = dustdem()
        .args([
            "run",
            config.to_str().unwrap(),
            "--out",
            killed.to_str().unwrap(),
            "--backend",
            backend,
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Wait until a checkpoint exists and more rows have been written after it, then SIGKILL.
    let checkpoint = killed.join("checkpoint.bin");
    let start = Instant::now();
    loop {
        std::thread::sleep(Duration::from_millis(20));
        let rows =
            std::fs::read_to_string(killed.join("curve.csv")).map_or(0, |t| t.lines().count());
        if checkpoint.exists() && rows > 35 {
            break;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run finished before it could be killed"
        );
        assert!(start.elapsed() < Duration::from_secs(120));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let status = dustdem()
        .args([
            "resume",
            checkpoint.to_str().unwrap(),
            "--backend",
            backend,
            "--quiet",
        ])
        .status()
        .unwrap();
    assert!(status.success());
    for file in ["curve.csv", "profiles.csv"] {
        let a = std::fs::read(straight.join(file)).unwrap();
        let b = std::fs::read(killed.join(file)).unwrap();
        assert!(
            a == b,
            "{file} differs after kill + resume ({} vs {} bytes)",
            a.len(),
            b.len()
        );
    }
}
