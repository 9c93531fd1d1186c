//! The engine in the mixed precision (f32 arithmetic; split centres, double-f32 pointers, wall
//! points and tallies: DESIGN.md, "Precision") on a device made without f64, held to closed
//! forms where motion is free and to itself for determinism. Compressions against the CPU
//! reference are in tests/gpu_compression.rs.

mod common;

use common::*;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::{context_for_tests_with, ShaderF64};
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::shader::Precision;
use dustdem::experiment::collision::{
    analytic_sticking_speed, head_on_collision, sticking_threshold, Outcome,
};
use dustdem::model::{ContactLaw, Damping, WallFactors};
use dustdem::state::{Monomers, Wall};
use dustdem::state::{DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use glam::DVec3;

fn mixed(law: ContactLaw, dt: f64, m: Monomers, walls: Vec<Wall>) -> Option<GpuEngine> {
    let ctx = context_for_tests_with(ShaderF64::Refused)?;
    let e = GpuEngine::new(
        ctx,
        law,
        dt,
        m,
        walls,
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    );
    let e = e.unwrap();
    assert_eq!(e.precision, Precision::Mixed);
    Some(e)
}

/// The f32 nearest to x, as f64.
fn f32_of(x: f64) -> f64 {
    f64::from(x as f32)
}

#[test]
fn a_free_monomer_at_1_cm_per_s_moves_by_every_step() {
    // 0.6 µm radius, 60 µm from the origin (where an f32 coordinate's ulp is 3.7e-10 cm, more
    // than the step of 3e-10 cm: a plain f32 centre would not move at all).
    let law = undamped();
    let dt = 3e-10;
    let (x0, v) = (
        DVec3::new(6.1e-3, 6.2e-3, 6.3e-3),
        DVec3::new(1.0, -0.5, 0.25),
    );
    let mut m = Monomers::new(vec![x0]);
    m.velocity[0] = v;
    let Some(mut e) = mixed(law, dt, m, Vec::new()) else {
        return;
    };
    e.readback_every = 1000;
    let steps = 20_000u64;
    e.run(steps).unwrap();
    let x = e.positions()[0];
    // Each step adds the f32 product of the f32 velocity and the f32 dt, exactly (the offset
    // and its low part are a double-f32, 2⁻⁴⁸ of a voxel per step): the closed form with those
    // products, to the split's 2⁻⁴⁵ cm. The f64 closed form differs by their rounding,
    // at most 2⁻²³ of the travel per axis.
    for axis in 0..3 {
        let step = f32_of(f32_of(v[axis]) * f32_of(dt));
        let expected = x0[axis] + steps as f64 * f32_of(f32_of(v[axis]) * f32_of(dt));
        let travel = steps as f64 * v[axis].abs() * dt;
        let error = (x[axis] - expected).abs();
        eprintln!("axis {axis}: travel {travel:.3e} cm, off the f32-step closed form by {error:.2e} cm (step {step:.6e})");
        assert!(error <= 1e-13, "axis {axis}: {error:e}");
        let exact = x0[axis] + v[axis] * dt * steps as f64;
        assert!((x[axis] - exact).abs() <= travel * 2f64.powi(-23) + 1e-13);
    }
}

#[test]
fn a_wall_at_1_cm_per_s_moves_by_every_step() {
    let law = undamped();
    let dt = 3e-10;
    // A monomer far from the wall, so the wall moves alone.
    let m = Monomers::new(vec![DVec3::new(1e-3, 1e-3, 1e-3)]);
    let wall = Wall {
        name: "top".into(),
        point: DVec3::new(0.0, 0.0, 6.0e-3),
        normal: DVec3::NEG_Z,
        velocity: DVec3::new(0.0, 0.0, -1.0),
        constants: law.wall_constants(WallFactors::FULL),
    };
    let Some(mut e) = mixed(law, dt, m, vec![wall]) else {
        return;
    };
    e.readback_every = 1000;
    let steps = 20_000u64;
    e.run(steps).unwrap();
    let z = e.current_walls()[0].point.z;
    let expected = 6.0e-3 - steps as f64 * f32_of(f32_of(1.0) * f32_of(dt));
    let travel = steps as f64 * dt;
    eprintln!(
        "wall travel {travel:.3e} cm, off the f32-step closed form by {:.2e} cm",
        (z - expected).abs()
    );
    // The point is a double-f32 (2⁻⁴⁸ relative): exact sums of the f32 steps.
    assert!((z - expected).abs() <= 1e-13, "{z} vs {expected}");
    assert!((z - (6.0e-3 - travel)).abs() <= travel * 2f64.powi(-23) + 1e-13);
}

#[test]
fn the_mixed_precision_repeats_itself_to_the_bit() {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let dt = 2.5e-11;
    let m = moving_cluster(&law, 60.0, 11);
    let run = || {
        let mut e = mixed(law, dt, m.clone(), Vec::new())?;
        e.readback_every = 50;
        e.run(100).unwrap();
        Some(e.snapshot())
    };
    let Some(a) = run() else {
        return;
    };
    let b = run().unwrap();
    assert!(a.contacts.pair_contact_count() > 0);
    assert_eq!(a.monomers.position, b.monomers.position);
    assert_eq!(a.monomers.velocity, b.monomers.velocity);
    assert_eq!(a.contacts.pair, b.contacts.pair);
    assert_eq!(a.tally, b.tally);
}

/// The sticking speed of two monomers (head-on, no damping: the JKR loop's energy decides it)
/// in the mixed precision against the f64 one at the same step (the CPU reference, which the
/// exact GPU engine repeats bit for bit). The mixed engine must stick 0.1 % below the f64
/// threshold and separate 0.1 % above it: the threshold within 0.1 % (the target is 0.5 %).
/// A bisection to 10⁻⁵ found the same threshold as the f64 one (10.999239 cm/s, the closed form
/// 11.005855 at this step), in two minutes on lavapipe; two collisions take a fifth of that.
#[test]
fn the_sticking_speed_in_the_mixed_precision_is_the_f64_one() {
    if context_for_tests_with(ShaderF64::Refused).is_none() {
        return;
    }
    let law = undamped();
    let dt = 4e-12;
    let guess = analytic_sticking_speed(&law);
    let exact =
        sticking_threshold(&law, dt, 0.95 * guess, 1.05 * guess, 1e-6, CpuEngine::new).unwrap();
    let mixed = |speed: f64| {
        head_on_collision(&law, speed, dt, 5.0, |law, dt, m, w, ps, ws| {
            let ctx = context_for_tests_with(ShaderF64::Refused).unwrap();
            Ok(GpuEngine::new(ctx, law, dt, m, w, ps, ws)?)
        })
        .unwrap()
        .outcome
    };
    let (below, above) = (mixed(0.999 * exact), mixed(1.001 * exact));
    eprintln!(
        "f64 sticking speed {exact:.6} cm/s; mixed at −0.1 %: {below:?}, at +0.1 %: {above:?}"
    );
    assert_eq!(below, Outcome::Stuck);
    assert!(matches!(above, Outcome::Separated { .. }), "{above:?}");
}

/// The mixed precision's buffers as allocated: f32 where the exact precision has f64, except
/// what it keeps as double-f32 in the same bytes (pointers, anchors, tally) and the split
/// centres' two extra arrays. Per monomer with 12 pair and 3 wall slots: the eight vec4 state
/// arrays 256 → 128 B (+32 B voxel and low part), the three per-slot result vectors 96 → 48 B
/// per slot (12 slots: −576 B), the three per-wall-slot vectors 96 → 48 B (3 slots: −144 B).
#[test]
fn the_mixed_precision_takes_less_device_memory() {
    let law = undamped();
    let m = moving_cluster(&law, 0.5, 7);
    let n = m.len() as f64;
    let Some(ctx) = context_for_tests_with(ShaderF64::Required) else {
        return;
    };
    let exact = GpuEngine::new(
        ctx,
        law,
        1e-10,
        m.clone(),
        Vec::new(),
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap();
    let mixed = mixed(law, 1e-10, m, Vec::new()).unwrap();
    let (a, b) = (exact.device_bytes() as f64, mixed.device_bytes() as f64);
    eprintln!(
        "device bytes per monomer: exact {:.0}, mixed {:.0}",
        a / n,
        b / n
    );
    let saved = (a - b) / n;
    // 128 − 32 + 576 + 144 = 816 B per monomer, and what the buffers of fixed size save (the
    // walls' uniform, the diagnostics block, the per-block partials and row sums: under 2 kB
    // in all; measured 850 B per monomer at N = 50 with them).
    assert!((816.0..=816.0 + 2000.0 / n).contains(&saved), "{saved}");
}
