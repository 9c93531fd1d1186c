//! The integrate pass against its CPU twin, and the inelastic corrections on the GPU landing
//! on the critical lengths.

use crate::support::{crafted, exact, gpu_of, perpendicular, tables_match, turn, worst};
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::kernels::Kernel;
use dustdem::state::ContactTable;

#[test]
fn integrate_matches_its_cpu_twin() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    let mut cpu = CpuEngine::from_state(state.state.clone());
    let passes = [
        Kernel::IntegrateKick,
        Kernel::IntegratePairs,
        Kernel::IntegrateDrift,
    ];
    for pass in passes {
        cpu.run_pass(pass).unwrap();
    }
    gpu.dispatch(&passes);
    let tol = if exact(&gpu) { 0.0 } else { 1e-14 };
    let m = gpu.monomers();
    let errs = [
        worst(&cpu.monomers.position, &m.position, 0.0),
        worst(&cpu.monomers.velocity, &m.velocity, 1e-3),
        worst(&cpu.monomers.angular_velocity, &m.angular_velocity, 1.0),
    ];
    let history = tables_match(
        &cpu.contacts,
        &gpu.contacts(),
        if exact(&gpu) { 0.0 } else { 1e-13 },
    );
    eprintln!("integrate: position, velocity, spin {errs:?}; history {history:e}");
    assert!(errs.iter().all(|e| *e <= tol), "{errs:?}");
    for (a, b) in cpu.walls.iter().zip(gpu.current_walls()) {
        assert_eq!(a.point, b.point);
    }
}

/// |ξ|, |ζ| and |φ| of every pair contact, and |ξ|, |ζ|, ξ_crit, ζ_crit of every wall contact,
/// in slot order.
fn displacements(e: &CpuEngine, table: &ContactTable) -> (Vec<[f64; 3]>, Vec<[f64; 4]>) {
    use dustdem::model::{rolling, sliding, wall};
    let (r, x) = (e.law.radius, &e.monomers.position);
    let mut pairs = Vec::new();
    let mut walls = Vec::new();
    for i in 0..x.len() {
        for c in table.pairs_of(i) {
            let nc = (x[i] - x[c.partner as usize]).normalize();
            pairs.push([
                rolling::rolling_displacement(c.n1, c.n2, e.law.pair.reduced_radius).length(),
                sliding::sliding_displacement(c.n1, c.n2, nc, r, r).length(),
                c.twist.abs(),
            ]);
        }
        for c in table.walls_of(i) {
            let w = &e.walls[c.wall as usize];
            walls.push([
                wall::wall_rolling_displacement(c.n1, w.normal, r).length(),
                wall::wall_sliding_displacement(x[i], c.n1, r, c.anchor, w.normal).length(),
                w.constants.xi_crit,
                w.constants.zeta_crit,
            ]);
        }
    }
    (pairs, walls)
}

#[test]
fn inelastic_corrections_on_the_gpu_land_on_the_critical_lengths() {
    // The crafted state turns n₁ alone for rolling, which also slides; add pure rolling
    // (n₁ and n₂ turned by opposite angles: ξ grows, ζ stays 0) on every 7th monomer's first
    // contact, so the rolling correction is seen alone.
    let mut state = crafted().cpu;
    let x = state.monomers.position.clone();
    let slots = state.contacts.pair_slots;
    for i in (0..x.len()).step_by(7) {
        if state.contacts.pair_count[i] > 0 {
            let c = &mut state.contacts.pair[i * slots];
            let nc = (x[i] - x[c.partner as usize]).normalize();
            let axis = perpendicular(nc, i);
            c.n1 = turn(-nc, axis, 0.01);
            c.n2 = turn(nc, axis, -0.01);
        }
    }
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    gpu.clear_work_lists();
    gpu.dispatch(&[
        Kernel::ContactsScan,
        Kernel::ForcesCorrections,
        Kernel::Forces,
        Kernel::WallContacts,
        Kernel::WallForces,
    ]);
    let after_table = gpu.contacts();
    let k = state.law.pair;
    let (before, before_walls) = displacements(&state, &state.contacts);
    let (after, after_walls) = displacements(&state, &after_table);
    let on_limit = |x: f64, crit: f64| (x / crit - 1.0).abs() < 1e-9;
    let mut corrected = [0; 5];
    for (b, a) in before.iter().zip(&after) {
        // Rolling alone (a sliding correction that follows moves ξ at second order).
        if b[0] > k.xi_crit && b[1] <= k.zeta_crit {
            assert!(
                on_limit(a[0], k.xi_crit),
                "rolling {:e} vs {:e}",
                a[0],
                k.xi_crit
            );
            corrected[0] += 1;
        }
        if b[1] > k.zeta_crit {
            assert!(on_limit(a[1], k.zeta_crit), "sliding {:e}", a[1]);
            corrected[1] += 1;
        }
        if b[2] > k.phi_crit {
            assert_eq!(a[2], k.phi_crit);
            corrected[2] += 1;
        }
    }
    for (b, a) in before_walls.iter().zip(&after_walls) {
        if b[0] > b[2] {
            assert!(on_limit(a[0], b[2]), "wall rolling {:e}", a[0]);
            corrected[3] += 1;
        }
        if b[1] > b[3] {
            assert!(on_limit(a[1], b[3]), "wall sliding {:e}", a[1]);
            corrected[4] += 1;
        }
    }
    eprintln!("corrected on the GPU: pair rolling, sliding, twisting, wall rolling, sliding: {corrected:?}");
    assert!(corrected.iter().all(|c| *c > 0), "{corrected:?}");
    let n = state.monomers.len();
    for i in 0..n {
        for c in after_table.pairs_of(i) {
            assert!((c.n1.length() - 1.0).abs() < 1e-14 && (c.n2.length() - 1.0).abs() < 1e-14);
        }
        for c in after_table.walls_of(i) {
            assert!((c.n1.length() - 1.0).abs() < 1e-14);
        }
    }
}
