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

use common::*;
use dustdem::backend::cpu::neighbours::NeighbourList;
use dustdem::backend::cpu::workspace::Workspace;
use dustdem::backend::cpu::{contacts, forces, integrate, walls, CpuEngine};
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::kernels::Kernel;
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::model::{ContactLaw, Damping, WallFactors};
use dustdem::state::reduction as reduce;
use dustdem::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
use glam::{DQuat, DVec3};

const TALLY_TOLERANCE: f64 = 1e-12;

/// Unit vector perpendicular to `n`, chosen by `k`.
fn perpendicular(n: DVec3, k: usize) -> DVec3 {
    let a = n.any_orthonormal_vector();
    let b = n.cross(a);
    let angle = k as f64 * 0.7;
    a * angle.cos() + b * angle.sin()
}

fn turn(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    (DQuat::from_axis_angle(axis, angle) * v).normalize()
}

/// The crafted state and what it contains.
struct Crafted {
    cpu: CpuEngine,
}

fn crafted() -> Crafted {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let dt = 1e-10;
    let r = law.radius;
    let pos = tree_aggregate(&law, 500, 21);
    let mut m = Monomers::new(pos.clone());
    let mut rng = SplitMix64(5);
    for i in 0..m.len() {
        m.velocity[i] = rng.unit_vector() * (20.0 * rng.unit());
        m.angular_velocity[i] = rng.unit_vector() * (20.0 / r * rng.unit());
    }
    let mut zs: Vec<f64> = pos.iter().map(|p| p.z).collect();
    zs.sort_by(f64::total_cmp);
    let mut xs: Vec<f64> = pos.iter().map(|p| p.x).collect();
    xs.sort_by(f64::total_cmp);
    let end = law.wall_constants(WallFactors::FULL);
    let side = law.wall_constants(WallFactors {
        rolling: 0.5,
        sliding: 0.5,
        twisting: 0.5,
    });
    let walls = vec![
        Wall {
            name: "bottom".into(),
            point: DVec3::new(0.0, 0.0, zs[6] - r + 0.5 * end.delta0),
            normal: DVec3::Z,
            velocity: DVec3::ZERO,
            constants: end,
        },
        Wall {
            name: "x+".into(),
            point: DVec3::new(xs[xs.len() - 7] + r - 0.5 * side.delta0, 0.0, 0.0),
            normal: -DVec3::X,
            velocity: DVec3::new(-30.0, 0.0, 0.0),
            constants: side,
        },
    ];
    let mut cpu = CpuEngine::new(law, dt, m, walls, 12, 3).unwrap();
    cpu.run(2).unwrap();

    // Edit the contact table.
    let k = law.pair;
    let s = &mut cpu.state;
    let t = &mut s.contacts;
    let p = &s.monomers.position;
    let mut counter = 0usize;
    for i in 0..p.len() {
        let mut slot = 0;
        while slot < t.pair_count[i] as usize {
            let idx = i * t.pair_slots + slot;
            let mut c = t.pair[idx];
            let nc = (p[i] - p[c.partner as usize]).normalize();
            let axis = perpendicular(nc, counter);
            match counter % 7 {
                // Rolling past ξ_crit: turn n₁ alone.
                0 => c.n1 = turn(c.n1, axis, 3.0 * k.xi_crit / k.reduced_radius),
                // Sliding past ζ_crit: turn both pointers the same way.
                1 => {
                    let angle = 3.0 * k.zeta_crit / r;
                    c.n1 = turn(c.n1, axis, angle);
                    c.n2 = turn(c.n2, axis, angle);
                }
                2 => c.twist = 1.5 * k.phi_crit,
                3 => c.twist = -2.0 * k.phi_crit,
                // Elastic: small rolling and twist.
                4 => {
                    c.n1 = turn(c.n1, axis, 0.2 * k.xi_crit / k.reduced_radius);
                    c.twist = 0.3 * k.phi_crit;
                }
                // Missing from the table: the contacts pass forms it again.
                5 => {
                    let last = i * t.pair_slots + t.pair_count[i] as usize - 1;
                    t.pair[idx] = t.pair[last];
                    t.pair_count[i] -= 1;
                    counter += 1;
                    continue;
                }
                _ => {}
            }
            t.pair[idx] = c;
            counter += 1;
            slot += 1;
        }
    }
    // Stretched past −δ_c: pairs a little too far apart, entered as contacts.
    let mut stretched = 0;
    'outer: for i in 0..p.len() {
        for j in i + 1..p.len() {
            let d = (p[i] - p[j]).length();
            if d > 2.0 * r + k.delta_c && d < 2.2 * r && (t.pair_count[i] as usize) < t.pair_slots {
                let nc = (p[i] - p[j]) / d;
                let idx = i * t.pair_slots + t.pair_count[i] as usize;
                t.pair[idx] = PairContact {
                    partner: j as u32,
                    n1: -nc,
                    n2: nc,
                    twist: 0.0,
                };
                t.pair_count[i] += 1;
                stretched += 1;
                if stretched == 8 {
                    break 'outer;
                }
            }
        }
    }
    assert!(stretched > 0, "no pair to stretch");
    // Wall contacts: limits, and one too far from its wall.
    let mut w_counter = 0usize;
    for i in 0..p.len() {
        for slot in 0..t.wall_count[i] as usize {
            let idx = i * t.wall_slots + slot;
            let mut c = t.wall[idx];
            let wall = &s.walls[c.wall as usize];
            let kw = wall.constants;
            let axis = perpendicular(wall.normal, w_counter);
            match w_counter % 4 {
                0 => c.n1 = turn(c.n1, axis, 3.0 * kw.xi_crit / r),
                1 => c.anchor += axis * (3.0 * kw.zeta_crit),
                2 => c.twist = -1.5 * kw.phi_crit,
                _ => {}
            }
            t.wall[idx] = c;
            w_counter += 1;
        }
    }
    assert!(w_counter >= 4, "only {w_counter} wall contacts");
    // A monomer far above the floor that still has a floor contact: it breaks.
    let far = (0..p.len())
        .find(|&i| t.wall_count[i] == 0 && p[i].z > zs[6] + 10.0 * r)
        .unwrap();
    let floor = &s.walls[0];
    t.wall[far * t.wall_slots] = WallContact {
        wall: 0,
        n1: -floor.normal,
        anchor: p[far] - floor.normal * r,
        twist: 0.0,
    };
    t.wall_count[far] = 1;
    // A floor contact missing from the table: formed again.
    let touching = (0..p.len())
        .find(|&i| t.wall_count[i] == 1 && t.wall[i * t.wall_slots].wall == 0 && i != far)
        .unwrap();
    t.wall_count[touching] = 0;
    Crafted { cpu }
}

fn gpu_of(state: &CpuEngine) -> Option<GpuEngine> {
    gpu_laid_out(state, false)
}

/// The engine holding `state`, with its per-slot arrays split over three bindings if `split`.
fn gpu_laid_out(state: &CpuEngine, split: bool) -> Option<GpuEngine> {
    let ctx = context_for_tests()?;
    Some(
        GpuEngine::with_state_laid_out(
            ctx,
            state.law,
            state.dt,
            &state.monomers,
            &state.contacts,
            state.walls.clone(),
            split,
        )
        .unwrap(),
    )
}

fn exact(gpu: &GpuEngine) -> bool {
    gpu.ctx.float_mode == FloatMode::Exact
}

/// Largest |a − b| / max(|a|, |b|, floor) over the components, 0 when bit-identical.
fn rel(a: DVec3, b: DVec3, floor: f64) -> f64 {
    let d = (a - b).abs().max_element();
    if d == 0.0 {
        0.0
    } else {
        d / a.abs().max(b.abs()).max_element().max(floor)
    }
}

fn worst(a: &[DVec3], b: &[DVec3], floor: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| rel(*x, *y, floor))
        .fold(0.0, f64::max)
}

/// Contact tables equal slot for slot (partners, pointers, twist, anchors) up to `tol`.
fn tables_match(cpu: &ContactTable, gpu: &ContactTable, tol: f64) -> f64 {
    assert_eq!(cpu.pair_count, gpu.pair_count, "pair contact counts");
    assert_eq!(cpu.wall_count, gpu.wall_count, "wall contact counts");
    let mut w = 0.0f64;
    for i in 0..cpu.pair_count.len() {
        for (a, b) in cpu.pairs_of(i).iter().zip(gpu.pairs_of(i)) {
            assert_eq!(a.partner, b.partner, "partner of monomer {i}");
            w = w.max(rel(a.n1, b.n1, 1.0)).max(rel(a.n2, b.n2, 1.0));
            w = w.max((a.twist - b.twist).abs());
        }
        for (a, b) in cpu.walls_of(i).iter().zip(gpu.walls_of(i)) {
            assert_eq!(a.wall, b.wall, "wall of monomer {i}");
            w = w
                .max(rel(a.n1, b.n1, 1.0))
                .max(rel(a.anchor, b.anchor, 0.0));
            w = w.max((a.twist - b.twist).abs());
        }
    }
    assert!(w <= tol, "contact history differs by {w:e}");
    w
}

fn gpu_tally(gpu: &GpuEngine) -> (Dissipation, f64) {
    let mut d = Dissipation::default();
    let mut work = 0.0;
    for t in gpu.monomer_tallies() {
        d.breaking += t[0];
        d.forming += t[1];
        d.damping += t[2];
        d.rolling += t[3];
        d.sliding += t[4];
        d.twisting += t[5];
        d.walls += t[6];
        work += t[7];
    }
    (d, work)
}

fn assert_channel(name: &str, cpu: f64, gpu: f64) {
    let err = (cpu - gpu).abs() / cpu.abs().max(f64::MIN_POSITIVE);
    eprintln!("  {name}: cpu {cpu:.9e} gpu {gpu:.9e} (rel {err:.1e})");
    assert!(cpu != 0.0, "{name}: the state exercises it");
    assert!(err <= TALLY_TOLERANCE, "{name}: {cpu:e} vs {gpu:e}");
}

#[test]
fn integrate_matches_its_cpu_twin() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    let mut cpu = state.state.clone();
    let law: ContactLaw = cpu.law;
    integrate::integrate(
        cpu.dt,
        1.0 / law.mass,
        1.0 / law.moment_of_inertia,
        &mut cpu.monomers,
        &mut cpu.contacts,
        &mut cpu.walls,
    );
    gpu.dispatch(&[
        Kernel::IntegrateKick,
        Kernel::IntegratePairs,
        Kernel::IntegrateDrift,
    ]);
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

#[test]
fn contacts_match_their_cpu_twin() {
    let state = crafted().cpu;
    let Some(mut gpu) = gpu_of(&state) else {
        return;
    };
    let mut cpu = state.state.clone();
    let mut list = NeighbourList::new(2.0 * cpu.law.radius, 0.2 * cpu.law.radius);
    list.refresh(&cpu.monomers.position);
    let mut tally = Dissipation::default();
    contacts::contacts(
        &cpu.law,
        cpu.dt,
        &cpu.monomers,
        &cpu.walls,
        &list.pairs,
        &list.starts,
        &mut cpu.contacts,
        &mut tally,
    )
    .unwrap();
    // The contacts pass then applies the inelastic limits of the owners it lists, pair and
    // wall contacts (on the CPU, the starts of forces and wall_forces).
    for i in 0..cpu.monomers.len() {
        for slot in 0..cpu.contacts.pair_count[i] as usize {
            let c = &mut cpu.contacts.pair[i * cpu.contacts.pair_slots + slot];
            forces::apply_inelastic_limits(&cpu.law, &cpu.monomers, cpu.dt, i, c, &mut tally);
        }
        for slot in 0..cpu.contacts.wall_count[i] as usize {
            let c = &mut cpu.contacts.wall[i * cpu.contacts.wall_slots + slot];
            let wall = &cpu.walls[c.wall as usize];
            walls::apply_wall_inelastic_limits(
                &cpu.law,
                &cpu.monomers,
                cpu.dt,
                i,
                wall,
                c,
                &mut tally,
            );
        }
    }
    gpu.clear_work_lists();
    gpu.dispatch(&[
        Kernel::Neighbours,
        Kernel::NeighboursList,
        Kernel::ContactsScan,
        Kernel::Contacts,
    ]);
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
    let mut cpu = state.state.clone();
    let mut tally = Dissipation::default();
    let nw = cpu.walls.len();
    let (mut wall_force, mut wall_damping) = (vec![DVec3::ZERO; nw], vec![DVec3::ZERO; nw]);
    let mut workspace = Workspace::default();
    forces::forces(
        &cpu.law,
        cpu.dt,
        &mut cpu.monomers,
        &mut cpu.contacts,
        &mut tally,
        &mut workspace,
    );
    walls::wall_forces(
        &cpu.law,
        cpu.dt,
        &cpu.walls,
        &mut cpu.monomers,
        &mut cpu.contacts,
        &mut tally,
        &mut wall_force,
        &mut wall_damping,
        &mut workspace,
    );
    gpu.clear_work_lists();
    gpu.dispatch(&[
        Kernel::ContactsScan,
        Kernel::ForcesCorrections,
        Kernel::Forces,
        Kernel::WallContacts,
        Kernel::WallForces,
        Kernel::ReduceWallsFinal,
    ]);
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
    for (a, b) in wall_force.iter().zip(gpu.wall_force()) {
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
fn profiled_steps_are_ordinary_steps() {
    let state = crafted().cpu;
    let (Some(mut profiled), Some(mut plain)) = (gpu_of(&state), gpu_of(&state)) else {
        return;
    };
    let Some(times) = profiled.profile_passes(5).unwrap() else {
        eprintln!("notice: no timestamp queries inside passes on this device");
        return;
    };
    plain.run(5).unwrap();
    assert_eq!(times.len(), GpuEngine::passes().len());
    assert!(times.iter().all(|(_, s)| *s > 0.0), "{times:?}");
    assert_eq!(profiled.step, plain.step);
    assert_eq!(profiled.positions(), plain.positions());
    assert_eq!(profiled.diagnostics(), plain.diagnostics());
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

#[test]
fn per_slot_arrays_in_one_binding_or_split_over_three_give_the_same_bits() {
    // Large N (above 349 525 with 12 slots) split every per-slot array over three bindings;
    // smaller N keep them in one, and the tests above hold that layout to the CPU. Both
    // layouts, run 50 steps from the crafted aggregate, must agree to the bit.
    let state = crafted().cpu;
    let (Some(mut one), Some(mut split)) =
        (gpu_laid_out(&state, false), gpu_laid_out(&state, true))
    else {
        return;
    };
    assert!(one.sizes.one_slot_chunk() && !split.sizes.one_slot_chunk());
    one.run(50).unwrap();
    split.run(50).unwrap();
    assert_eq!(one.monomers(), split.monomers());
    assert_eq!(one.contacts(), split.contacts());
    assert!(one.contacts().pair_contact_count() > 0);
}

#[test]
fn work_lists_longer_than_one_dispatch_are_walked_with_a_stride() {
    // A pass over a work list has at most the device's workgroups per dimension (65 535 of 8
    // invocations); longer lists (N > 524 280, e.g. forming a 10⁶-monomer sample's first
    // contacts) are walked with a stride. Here the limit is one workgroup, and the crafted
    // aggregate starts with no contacts, so the first step lists every touching owner: the
    // result must equal the unlimited engine's to the bit.
    let mut state = crafted().cpu;
    let t = &state.contacts;
    state.contacts = ContactTable::new(state.monomers.len(), t.pair_slots, t.wall_slots);
    let (Some(mut plain), Some(mut limited)) = (gpu_of(&state), gpu_of(&state)) else {
        return;
    };
    limited.limit_work_groups(1);
    plain.run(20).unwrap();
    limited.run(20).unwrap();
    let formed = plain.contacts().pair_contact_count();
    eprintln!("{formed} pair contacts formed");
    assert!(formed > 100, "the first step formed many contacts");
    assert_eq!(plain.contacts(), limited.contacts());
    assert_eq!(plain.monomers(), limited.monomers());
}
