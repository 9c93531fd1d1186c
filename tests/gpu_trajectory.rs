//! Trajectory parity of the GPU engine with the CPU reference: the same initial state, the same
//! number of steps, positions compared along the way.
//!
//! In the exact float mode every force and torque is bit-identical to the CPU's (same operations
//! in the same order, the gather in the CPU's summation order), so the trajectories agree to the
//! bit and the accepted difference is zero. The tally and the wall forces are summed in another
//! order (per monomer, then over monomers); they are compared to a relative tolerance.

mod common;
mod gpu_support;

use common::*;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::model::{ContactLaw, Damping, WallFactors};
use dustdem::state::{Monomers, Wall};
use dustdem::state::{DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use glam::DVec3;

/// Largest accepted position difference, as a fraction of δ₀, in the exact mode: none.
const EXACT_TOLERANCE: f64 = 0.0;
/// The same in the relaxed mode (plain WGSL, fused operations): chaotic growth of ulp-level
/// differences over 2000 steps stays far below this.
const RELAXED_TOLERANCE: f64 = 1e-3;

fn tolerance(mode: FloatMode) -> f64 {
    match mode {
        FloatMode::Exact => EXACT_TOLERANCE,
        FloatMode::Relaxed => RELAXED_TOLERANCE,
    }
}

/// Runs both engines `steps` steps, comparing positions every `every` steps; returns the largest
/// difference as a fraction of δ₀ and the two engines' final CPU-side states.
fn compare(
    law: ContactLaw,
    dt: f64,
    monomers: Monomers,
    walls: Vec<Wall>,
    steps: u64,
    every: u64,
) -> Option<(f64, FloatMode, CpuEngine, GpuEngine)> {
    compare_in(None, law, dt, monomers, walls, steps, every)
}

/// As [`compare`], with the shaders in `mode` instead of the best the device offers.
fn compare_in(
    mode: Option<FloatMode>,
    law: ContactLaw,
    dt: f64,
    monomers: Monomers,
    walls: Vec<Wall>,
    steps: u64,
    every: u64,
) -> Option<(f64, FloatMode, CpuEngine, GpuEngine)> {
    let mut ctx = context_for_tests()?;
    if let Some(mode) = mode {
        ctx.float_mode = mode;
    }
    let mode = ctx.float_mode;
    let mut cpu = CpuEngine::new(
        law,
        dt,
        monomers.clone(),
        walls.clone(),
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap();
    let mut gpu = GpuEngine::new(
        ctx,
        law,
        dt,
        monomers,
        walls,
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap();
    gpu.readback_every = every;
    let mut worst = 0.0f64;
    let mut done = 0;
    while done < steps {
        cpu.run(every).unwrap();
        gpu.run(every).unwrap();
        done += every;
        let p = gpu.positions();
        for (a, b) in cpu.monomers.position.iter().zip(&p) {
            worst = worst.max((*a - *b).length() / law.pair.delta0);
        }
        assert_eq!(
            gpu.diagnostics().pair_contacts,
            cpu.contacts.pair_contact_count(),
            "step {done}"
        );
        assert_eq!(
            gpu.diagnostics().wall_contacts,
            cpu.contacts.wall_contact_count(),
            "step {done}"
        );
    }
    Some((worst, mode, cpu, gpu))
}

fn close(a: f64, b: f64, rel: f64, scale: f64) -> bool {
    (a - b).abs() <= rel * scale.max(a.abs()).max(b.abs())
}

#[test]
fn two_monomers_collide_and_stick_as_on_the_cpu() {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let mut m = pair_at_overlap(&law, -0.2 * law.pair.delta0);
    // Head-on at 5 cm/s with a sideways offset: normal, damping, rolling and sliding all act.
    m.velocity[0] = DVec3::new(2.5, 0.3, 0.0);
    m.velocity[1] = DVec3::new(-2.5, -0.3, 0.1);
    m.angular_velocity[0] = DVec3::new(0.0, 0.0, 2e4);
    let Some((worst, mode, cpu, gpu)) = compare(law, 1e-10, m, Vec::new(), 2000, 100) else {
        return;
    };
    eprintln!("two monomers, {mode:?}: worst |Δx| = {worst:.3e} δ₀");
    assert_eq!(cpu.contacts.pair_contact_count(), 1);
    assert!(worst <= tolerance(mode), "{worst:e} δ₀");
    let (e_cpu, e_gpu) = (cpu.energy(), gpu.energy());
    eprintln!(
        "energy balance cpu {:.6e} gpu {:.6e}",
        e_cpu.balance(),
        e_gpu.balance()
    );
    assert!(close(
        e_cpu.dissipated.damping,
        e_gpu.dissipated.damping,
        1e-12,
        0.0
    ));
}

#[test]
fn a_four_monomer_chain_follows_the_cpu() {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let d = 2.0 * law.radius - law.pair.delta0;
    let pos: Vec<DVec3> = (0..4).map(|k| DVec3::new(k as f64 * d, 0.0, 0.0)).collect();
    let mut m = Monomers::new(pos);
    // Bend and twist the chain: the ends move sideways and spin.
    m.velocity[0] = DVec3::new(0.0, 30.0, 0.0);
    m.velocity[3] = DVec3::new(0.0, 0.0, -30.0);
    m.angular_velocity[1] = DVec3::new(3e5, 0.0, 0.0);
    let Some((worst, mode, cpu, _gpu)) = compare(law, 1e-10, m, Vec::new(), 2000, 250) else {
        return;
    };
    eprintln!(
        "4-monomer chain, {mode:?}: worst |Δx| = {worst:.3e} δ₀; tally {:?}",
        cpu.tally
    );
    assert!(worst <= tolerance(mode), "{worst:e} δ₀");
}

/// A 200-monomer tree aggregate with random velocities between a resting floor and a moving
/// lid: contacts form, break and slip, on monomers and on the walls.
fn aggregate_between_walls(law: &ContactLaw) -> (Monomers, Vec<Wall>) {
    let law = *law;
    let pos = tree_aggregate(&law, 200, 3);
    let mut m = Monomers::new(pos.clone());
    let mut rng = SplitMix64(99);
    for i in 0..m.len() {
        m.velocity[i] = rng.unit_vector() * (40.0 * rng.unit());
        m.angular_velocity[i] = rng.unit_vector() * (40.0 / law.radius * rng.unit());
    }
    let z_min = pos.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let z_max = pos.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
    let end = law.wall_constants(WallFactors::FULL);
    let walls = vec![
        Wall {
            name: "bottom".into(),
            point: DVec3::new(0.0, 0.0, z_min - law.radius + 0.5 * end.delta0),
            normal: DVec3::Z,
            velocity: DVec3::ZERO,
            constants: end,
        },
        Wall {
            name: "top".into(),
            point: DVec3::new(0.0, 0.0, z_max + law.radius),
            normal: -DVec3::Z,
            velocity: DVec3::new(0.0, 0.0, -500.0),
            constants: end,
        },
    ];
    (m, walls)
}

#[test]
fn a_200_monomer_aggregate_between_walls_follows_the_cpu() {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let (m, walls) = aggregate_between_walls(&law);
    let Some((worst, mode, cpu, gpu)) = compare(law, 1e-10, m, walls, 2000, 100) else {
        return;
    };
    let t = cpu.tally;
    eprintln!(
        "200 monomers, {mode:?}: worst |Δx| = {worst:.3e} δ₀; contacts {} + {} on walls; tally {t:?}",
        cpu.contacts.pair_contact_count(),
        cpu.contacts.wall_contact_count()
    );
    assert!(worst <= tolerance(mode), "{worst:e} δ₀");
    assert!(cpu.contacts.wall_contact_count() > 0);
    let g = gpu.diagnostics();
    let scale = t.total().abs();
    for (name, a, b) in [
        ("breaking", t.breaking, g.tally.breaking),
        ("forming", t.forming, g.tally.forming),
        ("damping", t.damping, g.tally.damping),
        ("rolling", t.rolling, g.tally.rolling),
        ("sliding", t.sliding, g.tally.sliding),
        ("twisting", t.twisting, g.tally.twisting),
        ("walls", t.walls, g.tally.walls),
        ("wall work", cpu.wall_work, g.wall_work),
    ] {
        eprintln!("  {name}: cpu {a:.6e} gpu {b:.6e}");
        assert!(close(a, b, 1e-9, scale * 1e-3), "{name}: {a:e} vs {b:e}");
    }
    for (a, b) in cpu.wall_force.iter().zip(gpu.wall_force()) {
        eprintln!("  wall force cpu {a:?} gpu {b:?}");
        assert!((*a - *b).length() <= 1e-12 * a.length().max(law.pair.f_c));
    }
}

/// The relaxed float mode (plain WGSL: the driver may fuse and reassociate) on the same run:
/// not bit-identical, but within [`RELAXED_TOLERANCE`] of δ₀.
#[test]
fn the_relaxed_float_mode_stays_close_to_the_cpu() {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let (m, walls) = aggregate_between_walls(&law);
    let Some((worst, mode, _, _)) =
        compare_in(Some(FloatMode::Relaxed), law, 1e-10, m, walls, 2000, 100)
    else {
        return;
    };
    eprintln!("200 monomers, {mode:?}: worst |Δx| = {worst:.3e} δ₀");
    assert!(worst <= RELAXED_TOLERANCE, "{worst:e} δ₀");
}
