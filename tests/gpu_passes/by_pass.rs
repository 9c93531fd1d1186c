//! Every entry point against its CPU twin, pass by pass: both engines start from the same
//! crafted state, run the same passes of the script before it (what it reads), then the pass
//! itself (`CpuEngine::run_pass`, `GpuEngine::dispatch`), and what the pass writes is compared.
//! In the exact float mode everything but the energy tally must be bit-identical (the tally is
//! summed per monomer on the device: 1e-12 of each channel, see the file's root).

use crate::support::{assert_channel, crafted, exact, gpu_of, gpu_tally, tables_match, worst};
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::interface::Binding;
use dustdem::backend::gpu::layout;
use dustdem::backend::script::{Kernel, STEP};
use glam::DVec3;
use std::collections::BTreeSet;

/// The CPU and GPU engines holding the crafted state, as an upload leaves it: the neighbour
/// lists due for a rebuild, the pair tests made on the state as it is, the work lists empty.
fn engines(edit: impl Fn(&mut CpuEngine)) -> Option<(CpuEngine, GpuEngine)> {
    let mut state = crafted().cpu;
    edit(&mut state);
    let gpu = gpu_of(&state)?;
    let mut cpu = CpuEngine::from_state(state.state.clone());
    cpu.neighbours.rebuild_due = true;
    // The device's per-monomer tallies start at zero after an upload.
    cpu.state.tally = Default::default();
    Some((cpu, gpu))
}

/// Runs `passes` on both engines, in order. The device's lists are emptied before a scan, as
/// `integrate_drift` does (the upload leaves those of a finished step).
fn run(cpu: &mut CpuEngine, gpu: &mut GpuEngine, passes: &[Kernel]) {
    for &pass in passes {
        cpu.run_pass(pass).unwrap();
        if pass == Kernel::ContactsScan {
            gpu.clear_work_lists();
        }
        gpu.dispatch(&[pass]);
    }
}

/// Both engines after `before`, then `pass`.
fn after(pass: Kernel, before: &[Kernel]) -> Option<(CpuEngine, GpuEngine)> {
    let (mut cpu, mut gpu) = engines(|_| {})?;
    run(&mut cpu, &mut gpu, before);
    run(&mut cpu, &mut gpu, &[pass]);
    Some((cpu, gpu))
}

/// The step's passes from `first` to `last` inclusive, as the step script runs them.
fn step_passes(first: Kernel, last: Kernel) -> &'static [Kernel] {
    let at = |k| {
        STEP.iter()
            .position(|&p| p == k)
            .expect("a pass of the step")
    };
    &STEP[at(first)..=at(last)]
}

/// The neighbour passes.
fn lists() -> &'static [Kernel] {
    step_passes(Kernel::Neighbours, Kernel::NeighboursList)
}

/// The passes of a step up to the owners' work list: what the contact passes read.
fn scanned() -> &'static [Kernel] {
    step_passes(Kernel::Neighbours, Kernel::ContactsScan)
}

/// The passes of a step up to the gather: what the wall sums and the start passes read.
fn gathered() -> &'static [Kernel] {
    step_passes(Kernel::Neighbours, Kernel::WallForces)
}

fn same_monomers(cpu: &CpuEngine, gpu: &GpuEngine) {
    let m = gpu.monomers();
    let tol = if exact(gpu) { 0.0 } else { 1e-14 };
    let c = &cpu.monomers;
    let errs = [
        worst(&c.position, &m.position, 0.0),
        worst(&c.velocity, &m.velocity, 1e-3),
        worst(&c.angular_velocity, &m.angular_velocity, 1.0),
        worst(&c.force, &m.force, cpu.law.pair.f_c * 1e-6),
        worst(
            &c.torque,
            &m.torque,
            cpu.law.pair.f_c * cpu.law.radius * 1e-6,
        ),
        worst(&c.damping_force, &m.damping_force, cpu.law.pair.f_c * 1e-6),
    ];
    assert!(errs.iter().all(|e| *e <= tol), "{errs:?}");
}

fn same_table(cpu: &CpuEngine, gpu: &GpuEngine) {
    tables_match(
        &cpu.contacts,
        &gpu.contacts(),
        if exact(gpu) { 0.0 } else { 1e-12 },
    );
}

/// The wall contacts' forces as the contacts pass (or `wall_contacts`) left them per slot;
/// returns how many were compared.
fn same_wall_results(cpu: &CpuEngine, gpu: &GpuEngine) -> usize {
    let device = gpu.slot_wall_forces();
    let ws = cpu.contacts.wall_slots;
    let mut compared = 0;
    for i in 0..cpu.monomers.len() {
        let slots = i * ws..i * ws + cpu.contacts.wall_count[i] as usize;
        for (host, d) in cpu.workspace.wall_result[slots.clone()]
            .iter()
            .zip(&device[slots])
        {
            assert_eq!(host.force, *d, "a wall contact of monomer {i}");
            compared += 1;
        }
    }
    compared
}

fn gpu_pair_tests(gpu: &GpuEngine) -> Vec<u32> {
    gpu.read_binding(Binding::PairTests, gpu.monomers().len())
}

/// The contacts work list the device's scan left, sorted (its order is the atomics').
fn gpu_work(gpu: &GpuEngine) -> Vec<u32> {
    let lengths: Vec<u32> = gpu.read_binding(Binding::Work, layout::WORK_LISTS);
    let n = gpu.monomers().len();
    let list: Vec<u32> = gpu.read_binding(Binding::WorkList, n);
    let mut items = list[..lengths[layout::WORK_CONTACTS] as usize].to_vec();
    items.sort_by_key(|w| w & layout::OWNER_INDEX as u32);
    items
}

fn rebuild_flag(gpu: &GpuEngine) -> bool {
    let flags: Vec<u32> = gpu.read_binding(Binding::Flags, layout::FLAG_REBUILD + 1);
    flags[layout::FLAG_REBUILD] != layout::NO_MONOMER
}

#[test]
fn integrate_kick() {
    let Some((cpu, gpu)) = after(Kernel::IntegrateKick, &[]) else {
        return;
    };
    same_monomers(&cpu, &gpu);
    same_table(&cpu, &gpu);
    assert!(gpu_pair_tests(&gpu).iter().all(|t| *t == 0));
    assert!(cpu.workspace.pair_tests.iter().all(|t| *t == 0));
}

#[test]
fn integrate_kick_with_wall_sums() {
    let Some((cpu, mut gpu)) = after(Kernel::IntegrateKickWithWallSums, gathered()) else {
        return;
    };
    same_monomers(&cpu, &gpu);
    let d = gpu.refresh_diagnostics().unwrap();
    assert!(cpu.wall_force.iter().all(|f| *f != DVec3::ZERO));
    assert_eq!(cpu.wall_force, d.wall_force);
}

#[test]
fn integrate_pairs() {
    let Some((cpu, gpu)) = after(Kernel::IntegratePairs, &[Kernel::IntegrateKick]) else {
        return;
    };
    same_table(&cpu, &gpu);
    let tests = gpu_pair_tests(&gpu);
    let bits = |b: u32| tests.iter().filter(|t| *t & b != 0).count();
    eprintln!(
        "pair tests: {} breaking, {} beyond a limit",
        bits(dustdem::backend::script::PAIR_TEST_BREAKS),
        bits(dustdem::backend::script::PAIR_TEST_BEYOND)
    );
    assert!(bits(1) > 0 && bits(2) > 0);
    assert_eq!(cpu.workspace.pair_tests, tests);
}

#[test]
fn integrate_drift() {
    // One monomer fast enough to leave half the skin in one step: the drift asks for a rebuild.
    let edit = |e: &mut CpuEngine| e.monomers.velocity[17] = DVec3::new(0.0, 0.0, 1e6);
    let Some((mut cpu, mut gpu)) = engines(edit) else {
        return;
    };
    let passes = [Kernel::IntegrateKick, Kernel::IntegratePairs];
    run(&mut cpu, &mut gpu, &passes);
    cpu.neighbours.rebuild_due = false;
    let flags: Vec<u32> = gpu.read_binding(Binding::Flags, layout::FLAG_REBUILD + 1);
    assert_ne!(
        flags[layout::FLAG_REBUILD],
        layout::NO_MONOMER,
        "due after the upload"
    );
    run(&mut cpu, &mut gpu, &[Kernel::IntegrateDrift]);
    same_monomers(&cpu, &gpu);
    for (a, b) in cpu.walls.iter().zip(gpu.current_walls()) {
        assert_eq!(a.point, b.point);
    }
    assert!(cpu.neighbours.rebuild_due && rebuild_flag(&gpu));
}

#[test]
fn neighbours() {
    let Some((cpu, gpu)) = after(Kernel::Neighbours, &[]) else {
        return;
    };
    // The device's buckets hash cells (a bucket may hold several); the CPU's cells sort by
    // key. Each CPU cell lies in one bucket, and each bucket is a union of CPU cells.
    let n = cpu.monomers.len();
    let counts: Vec<u32> = gpu.read_binding(Binding::BucketCount, gpu.sizes.table);
    let capacity = gpu.sizes.bucket_capacity;
    let items: Vec<u32> = gpu.read_binding(Binding::BucketItems, counts.len() * capacity);
    let mut bucket_of = vec![usize::MAX; n];
    for (b, &c) in counts.iter().enumerate() {
        for &i in &items[b * capacity..b * capacity + c as usize] {
            bucket_of[i as usize] = b;
        }
    }
    assert!(
        bucket_of.iter().all(|b| *b != usize::MAX),
        "every monomer in a bucket"
    );
    let cells = &cpu.neighbours.cells;
    assert_eq!(cells.len(), n);
    let mut in_bucket = vec![BTreeSet::new(); counts.len()];
    for w in cells.windows(2) {
        if w[0].0 == w[1].0 {
            assert_eq!(bucket_of[w[0].1 as usize], bucket_of[w[1].1 as usize]);
        }
    }
    for (key, i) in cells {
        in_bucket[bucket_of[*i as usize]].insert(*key);
    }
    let cpu_count = |key: &[i64; 3]| cells.iter().filter(|(k, _)| k == key).count();
    for (b, keys) in in_bucket.iter().enumerate() {
        let total: usize = keys.iter().map(cpu_count).sum();
        assert_eq!(total, counts[b] as usize, "bucket {b}");
    }
}

#[test]
fn neighbours_list() {
    let Some((cpu, gpu)) = after(Kernel::NeighboursList, &[Kernel::Neighbours]) else {
        return;
    };
    let n = cpu.monomers.len();
    let cap = layout::NEIGHBOUR_CAPACITY;
    let counts: Vec<u32> = gpu.read_binding(Binding::NeighbourCount, n);
    let lists: Vec<u32> = gpu.read_binding(Binding::NeighbourList, n * cap);
    let list = &cpu.neighbours;
    let mut listed = 0;
    for i in 0..n {
        let device = &lists[i * cap..i * cap + counts[i] as usize];
        let host: Vec<u32> = list.pairs[list.starts[i] as usize..list.starts[i + 1] as usize]
            .iter()
            .map(|&(_, j)| j)
            .filter(|&j| !cpu.contacts.has_pair(i, j))
            .collect();
        assert_eq!(device, &host[..], "candidates of monomer {i}");
        listed += host.len();
    }
    assert!(listed > 100, "{listed} candidates");
    let reference: Vec<[f64; 4]> = gpu.read_binding(Binding::ReferencePosition, n);
    for (r, x) in reference.iter().zip(&list.reference) {
        assert_eq!(DVec3::from_slice(&r[..3]), *x);
    }
}

#[test]
fn contacts_scan() {
    let Some((cpu, gpu)) = after(Kernel::ContactsScan, lists()) else {
        return;
    };
    let work = gpu_work(&gpu);
    let kinds = [
        layout::OWNER_EVENTS,
        layout::OWNER_CORRECTIONS,
        layout::OWNER_WALLS,
    ];
    for bit in kinds {
        assert!(work.iter().any(|w| w & bit as u32 != 0), "{bit:x} listed");
    }
    assert_eq!(cpu.workspace.work, work);
    assert!(!cpu.neighbours.rebuild_due && !rebuild_flag(&gpu));
}

#[test]
fn contacts() {
    let Some((cpu, gpu)) = after(Kernel::Contacts, scanned()) else {
        return;
    };
    same_table(&cpu, &gpu);
    let (g, _) = gpu_tally(&gpu);
    for (name, c, d) in [
        ("breaking", cpu.tally.breaking, g.breaking),
        ("forming", cpu.tally.forming, g.forming),
        ("walls", cpu.tally.walls, g.walls),
        ("rolling", cpu.tally.rolling, g.rolling),
        ("sliding", cpu.tally.sliding, g.sliding),
        ("twisting", cpu.tally.twisting, g.twisting),
    ] {
        assert_channel(name, c, d);
    }
    assert!(same_wall_results(&cpu, &gpu) > 0);
}

#[test]
fn contacts_clear_tally() {
    let before = [scanned(), &[Kernel::Contacts]].concat();
    let Some((cpu, gpu)) = after(Kernel::ContactsClearTally, &before) else {
        return;
    };
    assert_eq!(cpu.tally, Default::default());
    assert!(gpu.monomer_tallies().iter().flatten().all(|t| *t == 0.0));
}

#[test]
fn contacts_pair_tests() {
    let Some((cpu, gpu)) = after(Kernel::ContactsPairTests, &[]) else {
        return;
    };
    let tests = gpu_pair_tests(&gpu);
    assert!(tests.iter().any(|t| *t != 0));
    assert_eq!(cpu.workspace.pair_tests, tests);
}

#[test]
fn forces_corrections() {
    let Some((cpu, gpu)) = after(Kernel::ForcesCorrections, scanned()) else {
        return;
    };
    same_table(&cpu, &gpu);
    let (g, _) = gpu_tally(&gpu);
    assert_channel("rolling", cpu.tally.rolling, g.rolling);
    assert_channel("sliding", cpu.tally.sliding, g.sliding);
    assert_channel("twisting", cpu.tally.twisting, g.twisting);
}

/// The device's per-slot pair results (one binding chunk at this size) as (force, damping,
/// owner torque, partner torque).
fn gpu_pair_results(gpu: &GpuEngine, slots: usize) -> Vec<[DVec3; 4]> {
    let read = |b| gpu.read_binding::<[f64; 4]>(b, slots);
    let (a, b, c) = (
        read(Binding::PairResultAChunk0),
        read(Binding::PairResultBChunk0),
        read(Binding::PairResultCChunk0),
    );
    (0..slots)
        .map(|k| {
            [
                DVec3::new(a[k][0], a[k][1], a[k][2]),
                DVec3::new(a[k][3], b[k][0], b[k][1]),
                DVec3::new(b[k][2], b[k][3], c[k][0]),
                DVec3::new(c[k][1], c[k][2], c[k][3]),
            ]
        })
        .collect()
}

#[test]
fn forces() {
    let Some((cpu, gpu)) = after(Kernel::Forces, scanned()) else {
        return;
    };
    let t = &cpu.contacts;
    let device = gpu_pair_results(&gpu, t.pair.len());
    let mut k = 0;
    for i in 0..cpu.monomers.len() {
        for slot in 0..t.pair_count[i] as usize {
            let r = cpu.workspace.pair_result[k];
            let host = [r.force, r.damping, r.torque_owner, r.torque_partner];
            let d = device[i * t.pair_slots + slot];
            if exact(&gpu) {
                assert_eq!(host, d, "contact {i}/{slot}");
            } else {
                assert!(worst(&host, &d, cpu.law.pair.f_c * 1e-6) <= 2e-8);
            }
            k += 1;
        }
    }
    assert!(k > 100, "{k} contacts");
}

#[test]
fn wall_contacts() {
    let Some((cpu, gpu)) = after(Kernel::WallContacts, scanned()) else {
        return;
    };
    same_table(&cpu, &gpu);
    let (g, _) = gpu_tally(&gpu);
    assert_channel("walls (inelastic)", cpu.tally.walls, g.walls);
    assert!(same_wall_results(&cpu, &gpu) > 0);
}

#[test]
fn wall_forces() {
    let before = [scanned(), &[Kernel::Contacts, Kernel::Forces]].concat();
    let Some((cpu, gpu)) = after(Kernel::WallForces, &before) else {
        return;
    };
    same_monomers(&cpu, &gpu);
    // The block sums: the device's first MAX_WALLS per block, the CPU's one per wall.
    let nw = cpu.walls.len();
    let blocks = cpu.monomers.len().div_ceil(layout::REDUCE_BLOCK);
    let partials: Vec<[f64; 4]> = gpu.read_binding(Binding::Partials, blocks * layout::MAX_WALLS);
    for b in 0..blocks {
        for w in 0..nw {
            let d = DVec3::from_slice(&partials[b * layout::MAX_WALLS + w][..3]);
            assert_eq!(
                cpu.workspace.wall_partials[b * nw + w],
                d,
                "block {b} wall {w}"
            );
        }
    }
}

#[test]
fn reduce_walls_final() {
    let Some((cpu, mut gpu)) = after(Kernel::ReduceWallsFinal, gathered()) else {
        return;
    };
    let d = gpu.refresh_diagnostics().unwrap();
    assert!(cpu.wall_force.iter().all(|f| *f != DVec3::ZERO));
    assert_eq!(cpu.wall_force, d.wall_force);
}

#[test]
fn integrate_start() {
    let Some((cpu, gpu)) = after(Kernel::IntegrateStart, gathered()) else {
        return;
    };
    same_monomers(&cpu, &gpu);
}

#[test]
fn integrate_clear_work() {
    let Some((cpu, gpu)) = after(Kernel::IntegrateClearWork, gathered()) else {
        return;
    };
    let (g, work) = gpu_tally(&gpu);
    assert_eq!((cpu.tally.damping, cpu.wall_work), (0.0, 0.0));
    assert_eq!((g.damping, work), (0.0, 0.0));
    assert!(
        cpu.tally.rolling != 0.0 && g.rolling != 0.0,
        "other channels kept"
    );
}
