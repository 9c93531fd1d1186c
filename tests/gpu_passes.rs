//! Per-pass parity: each WGSL pass against its CPU twin on identical inputs.
//!
//! The input is a 500-monomer tree aggregate with random velocities between walls, run a few
//! steps on the CPU, then edited so that one step meets contacts in every state: elastic ones,
//! ones past each inelastic limit (rolling, sliding, twisting; on monomers and on walls), pair
//! and wall contacts stretched past −δ_c (breaking), and touching pairs and wall contacts missing
//! from the table (forming). The test asserts that each kind is present, so it cannot pass
//! vacuously.
//!
//! Tolerances: in the exact float mode the passes do the CPU's operations in the CPU's order, so
//! positions, velocities, contact histories, forces and torques must be bit-identical and contact
//! sets equal slot for slot. The energy tally is summed per monomer first on the device (no f64
//! atomics), so its channels are compared to 1e-12 of the channel's magnitude (a few ulps of each
//! addend, summed over ≤ 10³ events).

mod common;
mod gpu_support;

// The modules live in tests/gpu_passes/ (loaded by path: src/backend/gpu/twins.rs reads this
// file and by_pass.rs for the tests that hold each entry point to its twin).
#[path = "gpu_passes/by_pass.rs"]
mod by_pass;
#[path = "gpu_passes/integrate_and_corrections.rs"]
mod integrate_and_corrections;
#[path = "gpu_passes/support.rs"]
mod support;
#[path = "gpu_passes/whole_steps.rs"]
mod whole_steps;

use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::kernels::Kernel;
use dustdem::state::reduction as reduce;
use glam::DVec3;
use support::{assert_channel, crafted, exact, gpu_of, gpu_tally, tables_match, worst};

/// Runs `passes` on the CPU engine holding `state` as an upload leaves the device (neighbour
/// lists due, tally at zero) and returns it.
fn cpu_after(state: &CpuEngine, passes: &[Kernel]) -> CpuEngine {
    let mut cpu = CpuEngine::from_state(state.state.clone());
    cpu.neighbours.rebuild_due = true;
    cpu.state.tally = Default::default();
    for &pass in passes {
        cpu.run_pass(pass).unwrap();
    }
    cpu
}

#[test]
fn contacts_match_their_cpu_twin() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    let passes = [
        Kernel::Neighbours,
        Kernel::NeighboursList,
        Kernel::ContactsScan,
        Kernel::Contacts,
    ];
    let cpu = cpu_after(&state, &passes);
    gpu.clear_work_lists();
    gpu.dispatch(&passes);
    let before = state.contacts.pair_contact_count();
    eprintln!(
        "contacts: {} pair contacts before, {} after; wall {} → {}",
        before,
        cpu.contacts.pair_contact_count(),
        state.contacts.wall_contact_count(),
        cpu.contacts.wall_contact_count()
    );
    tables_match(&cpu.contacts, &gpu.contacts(), 0.0);
    let (g, _) = gpu_tally(&gpu);
    let tally = cpu.tally;
    assert_channel("breaking", tally.breaking, g.breaking);
    assert_channel("forming", tally.forming, g.forming);
    assert_channel("walls (form, break, limits)", tally.walls, g.walls);
    assert_channel("rolling", tally.rolling, g.rolling);
    assert_channel("sliding", tally.sliding, g.sliding);
    assert_channel("twisting", tally.twisting, g.twisting);
}

#[test]
fn forces_and_walls_match_their_cpu_twins() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    // The corrections and wall contacts without the events (the step runs them in the
    // contacts pass), then the forces, the gather and the wall sums.
    let passes = [
        Kernel::Neighbours,
        Kernel::NeighboursList,
        Kernel::ContactsScan,
        Kernel::ForcesCorrections,
        Kernel::Forces,
        Kernel::WallContacts,
        Kernel::WallForces,
        Kernel::ReduceWallsFinal,
    ];
    let cpu = cpu_after(&state, &passes);
    gpu.clear_work_lists();
    gpu.dispatch(&passes);
    let tally = cpu.tally;
    // Per-monomer tallies before the read: reading the small block starts them afresh.
    let (g, _) = gpu_tally(&gpu);
    let reduced = gpu.refresh_diagnostics().unwrap().tally;
    let exact = exact(&gpu);
    let m = gpu.monomers();
    let f_scale = cpu.law.pair.f_c;
    let t_scale = cpu.law.pair.f_c * cpu.law.radius;
    let errs = [
        worst(&cpu.monomers.force, &m.force, f_scale * 1e-6),
        worst(&cpu.monomers.torque, &m.torque, t_scale * 1e-6),
        worst(
            &cpu.monomers.damping_force,
            &m.damping_force,
            f_scale * 1e-6,
        ),
    ];
    let history = tables_match(
        &cpu.contacts,
        &gpu.contacts(),
        if exact { 0.0 } else { 1e-12 },
    );
    eprintln!("forces: force, torque, damping {errs:?}; history {history:e}");
    // Relaxed mode: the JKR root next to the branch end is √ε-conditioned (1.5e-8).
    let tol = if exact { 0.0 } else { 2e-8 };
    assert!(errs.iter().all(|e| *e <= tol), "{errs:?}");
    assert_channel("rolling", tally.rolling, g.rolling);
    assert_channel("rolling (reduced)", tally.rolling, reduced.rolling);
    assert_channel("sliding (reduced)", tally.sliding, reduced.sliding);
    assert_channel("sliding", tally.sliding, g.sliding);
    assert_channel("twisting", tally.twisting, g.twisting);
    assert_channel("walls (inelastic)", tally.walls, g.walls);
    // Per-wall sums: both backends sum the per-slot forces in the blocks of 64 monomers of
    // `reduce_walls`, so the exact mode gives the same bits; the relaxed mode keeps the bound
    // it had before the CPU summed in that order.
    for (a, b) in cpu.wall_force.iter().zip(gpu.wall_force()) {
        eprintln!("  wall force cpu {a:?} gpu {b:?}");
        assert!(*a != DVec3::ZERO);
        if exact {
            assert_eq!(*a, *b);
        } else {
            assert!((*a - *b).length() <= 1e-12 * a.length().max(f_scale));
        }
    }
}

#[test]
fn reductions_match_their_cpu_twin_to_the_bit() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    gpu.clear_work_lists();
    gpu.dispatch(&[
        Kernel::ContactsScan,
        Kernel::Contacts,
        Kernel::Forces,
        Kernel::WallForces,
        Kernel::ReduceWallsFinal,
    ]);
    // The reductions' inputs as the device holds them, read before the small block is.
    let (table, tallies, slots) = (
        gpu.contacts(),
        gpu.monomer_tallies(),
        gpu.slot_wall_forces(),
    );
    let walls = reduce::reduce_walls(&table, &slots, gpu.walls.len());
    let sums = reduce::reduce_diagnostics(&tallies, &table);
    let d = gpu.refresh_diagnostics().unwrap().clone();
    assert!(
        walls.iter().all(|w| *w != DVec3::ZERO),
        "every wall is touched"
    );
    assert!(
        sums.tally.iter().filter(|t| **t != 0.0).count() >= 4,
        "{:?}",
        sums.tally
    );
    assert_eq!(d.wall_force, walls);
    let mut device = [d.wall_work; 8];
    device[..7].copy_from_slice(&d.tally.channels());
    assert_eq!(device.map(f64::to_bits), sums.tally.map(f64::to_bits));
    assert_eq!(d.pair_contacts, sums.pair_contacts);
    assert_eq!(d.wall_contacts, sums.wall_contacts);
}

#[test]
fn a_submission_of_several_steps_is_the_same_steps_one_by_one() {
    // Inside a submission each step's kick also adds the last step's wall sums
    // (integrate_kick_with_wall_sums); a single step runs GpuEngine::STEP as it is.
    let state = crafted().cpu;
    let (Some(mut batched), Some(mut single)) = (gpu_of(&state), gpu_of(&state)) else {
        return;
    };
    let steps = 7;
    batched.run(steps).unwrap();
    let mut sums = vec![DVec3::ZERO; single.walls.len()];
    for _ in 0..steps {
        single.step().unwrap();
        for (sum, f) in sums.iter_mut().zip(single.wall_force()) {
            *sum += *f;
        }
    }
    assert_eq!(batched.step, single.step);
    let (a, b) = (batched.monomers(), single.monomers());
    assert_eq!(a.position, b.position);
    assert_eq!(a.velocity, b.velocity);
    assert_eq!(a.angular_velocity, b.angular_velocity);
    assert_eq!(batched.contacts(), single.contacts());
    assert_eq!(batched.wall_force(), single.wall_force());
    // The submission's mean wall force: the per-step forces summed on the device in step order
    // (on the host here, in the same order), over the steps.
    let d = batched.diagnostics();
    assert_eq!(d.mean_steps, steps);
    assert!(sums.iter().any(|f| *f != DVec3::ZERO));
    for (mean, sum) in d.mean_wall_force.iter().zip(&sums) {
        assert_eq!(*mean, *sum / steps as f64);
    }
}
