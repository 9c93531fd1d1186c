//! Monomer–wall contacts (their law, one monomer's contacts at a time, is law/walls.rs) and
//! the gather of every monomer's forces:
//! the twins of `wall_contacts` and `wall_forces` in shaders/passes/walls.wgsl and of
//! `reduce_walls_final` in shaders/passes/reduce.wgsl.
//!
//! As on the device: the contacts pass evaluates each monomer's wall contacts into per-slot
//! results ([`wall_contacts_of`]); `wall_forces` gathers per monomer the pair results (the
//! contacts it is the partner of, by owner and slot, then its own slots), then its wall
//! results in slot order, books the step's work and sums the wall forces per block of
//! [`REDUCE_BLOCK`] monomers; `reduce_walls_final` adds the blocks in order. So nothing depends
//! on the thread count and the forces equal the device's bits.

use super::integrate::NextKick;
use crate::backend::cpu::chunking::{split_len, CHUNK};
use crate::backend::cpu::law::results::WallResult;
use crate::backend::cpu::law::walls::wall_contacts_of;
use crate::backend::cpu::workspace::Workspace;
use crate::backend::script::{OWNER_INDEX, OWNER_WALLS};
use crate::model::ContactLaw;
use crate::state::reduction::{add_wall_slots_of, reduce_walls_final_from, WallRows, REDUCE_BLOCK};
use crate::state::{ContactTable, Dissipation, Monomers, Wall};
use glam::DVec3;
use rayon::prelude::*;

/// [`wall_contacts_of`] for the monomers `contacts_scan` listed with [`OWNER_WALLS`], without
/// their contact events: the step does it in the contacts pass, after the events; this lets
/// the forces be tested on a state whose events have not run. Returns what the limits
/// dissipated.
pub fn wall_contacts(
    law: &ContactLaw,
    dt: f64,
    walls: &[Wall],
    monomers: &Monomers,
    table: &mut ContactTable,
    work: &[u32],
    workspace: &mut Workspace,
) -> Dissipation {
    let ws = table.wall_slots;
    workspace.size_wall_results(monomers.len() * ws);
    let mut tally = Dissipation::default();
    for &item in work.iter().filter(|w| *w & OWNER_WALLS != 0) {
        let i = (item & OWNER_INDEX) as usize;
        let slots = i * ws..i * ws + table.wall_count[i] as usize;
        wall_contacts_of(
            law,
            dt,
            walls,
            monomers,
            i,
            &mut table.wall[slots.clone()],
            (&mut workspace.wall_result[slots], &[]),
            Some(&mut tally),
        );
    }
    tally
}

/// Every monomer's force, damping force and torque: the pair results it is the partner of (in
/// owner and slot order, negated; the partner's torque), its own (the owner's torque), then its
/// wall results in slot order. Books the damping work of the step by the trapezoid rule,
/// ½ (F_d(n) + F_d(n+1))·v dt per monomer, summed per chunk and over chunks in order (which
/// matches the leap-frog's kinetic energy change up to a bounded, telescoping term), and sums
/// the wall forces per block for `reduce_walls_final`.
///
/// With `next_kick` (the CPU step between two steps of one run), each monomer then gets the
/// next step's `integrate_kick` at once, its forces still in registers: the same operations on
/// the same values, one sweep over the monomers fewer (docs/guide/src/benchmarks.md, "CPU
/// engine: the kick joined to the gather"). The table is mutable for that kick's wall-contact pointers.
pub fn wall_forces(
    dt: f64,
    walls: &[Wall],
    monomers: &mut Monomers,
    table: &mut ContactTable,
    workspace: &mut Workspace,
    next_kick: Option<NextKick>,
) {
    let n = monomers.len();
    // Per block one sum per wall (at least one, so that the chunks below exist without walls).
    let stride = walls.len().max(1);
    let blocks = n.div_ceil(REDUCE_BLOCK);
    let mut partials = std::mem::take(&mut workspace.wall_partials);
    let mut damping_partials = std::mem::take(&mut workspace.wall_damping_partials);
    for p in [&mut partials, &mut damping_partials] {
        p.clear();
        p.resize(blocks * stride, DVec3::ZERO);
    }
    if next_kick.is_some() {
        // integrate_kick's length for the next pairs pass, which writes every owner's tests
        // (so they need no clearing here).
        workspace.pair_tests.resize(n, 0);
    }
    let ws = table.wall_slots;
    let ws_ref = &*workspace;
    let (wall_rows, wall_counts) = (&mut table.wall, &table.wall_count);
    let pair_counts = &table.pair_count;
    let m = Moving::of(monomers);
    let chunk_work: Vec<f64> = (
        m.velocity.par_chunks_mut(CHUNK),
        m.spin.par_chunks_mut(CHUNK),
        m.force.par_chunks_mut(CHUNK),
        m.damping.par_chunks_mut(CHUNK),
        m.torque.par_chunks_mut(CHUNK),
        partials.par_chunks_mut(CHUNK / REDUCE_BLOCK * stride),
        damping_partials.par_chunks_mut(CHUNK / REDUCE_BLOCK * stride),
        wall_rows.par_chunks_mut(CHUNK * ws),
        wall_counts.par_chunks(CHUNK),
    )
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .map(
            |(
                chunk,
                (velocity, spin, force, damping, torque, sums, damping_sums, rows, counts),
            )| {
                let first = chunk * CHUNK;
                let mut work = 0.0;
                let results = &ws_ref.wall_result;
                for k in 0..force.len() {
                    let i = first + k;
                    let wall_rows = WallRows {
                        rows,
                        counts,
                        slots: ws,
                        first,
                    };
                    let block_sums = (&mut *sums, &mut *damping_sums);
                    add_to_block_sums(wall_rows, results, k, block_sums);
                    let (f, fd, t) = gather(i, ws_ref, pair_counts[i], ws, counts[k]);
                    work += 0.5 * (damping[k] + fd).dot(velocity[k] * dt);
                    force[k] = f;
                    damping[k] = fd;
                    torque[k] = t;
                    if let Some(kick) = &next_kick {
                        let scales = (m.mass_scale[i], m.inertia_scale[i]);
                        let row = &mut rows[k * ws..k * ws + counts[k] as usize];
                        kick.kick((f, t), scales, (&mut velocity[k], &mut spin[k]), row, walls);
                    }
                }
                work
            },
        )
        .collect();
    let mut damping_work = 0.0;
    for w in chunk_work {
        damping_work += w;
    }
    workspace.damping_work = damping_work;
    workspace.wall_partials = partials;
    workspace.wall_damping_partials = damping_partials;
}

/// The chunk's `k`-th monomer's wall results added to its block's sums, force and damping
/// (`sums` holds the chunk's blocks, one sum per wall each): `reduce_walls_block_of` monomer
/// by monomer, as the gather reaches each.
fn add_to_block_sums(
    rows: WallRows,
    results: &[WallResult],
    k: usize,
    (sums, damping_sums): (&mut [DVec3], &mut [DVec3]),
) {
    let stride = sums.len() / rows.counts.len().div_ceil(REDUCE_BLOCK);
    let block = k / REDUCE_BLOCK * stride..(k / REDUCE_BLOCK + 1) * stride;
    let i = rows.first + k;
    add_wall_slots_of(rows, |s| results[s].force, i, &mut sums[block.clone()]);
    add_wall_slots_of(rows, |s| results[s].damping, i, &mut damping_sums[block]);
}

/// The monomer arrays `wall_forces` writes (and, kicking, the velocities), and the scales it
/// reads.
struct Moving<'a> {
    velocity: &'a mut [DVec3],
    spin: &'a mut [DVec3],
    force: &'a mut [DVec3],
    damping: &'a mut [DVec3],
    torque: &'a mut [DVec3],
    mass_scale: &'a [f64],
    inertia_scale: &'a [f64],
}

impl<'a> Moving<'a> {
    fn of(m: &'a mut Monomers) -> Self {
        Moving {
            velocity: &mut m.velocity,
            spin: &mut m.angular_velocity,
            force: &mut m.force,
            damping: &mut m.damping_force,
            torque: &mut m.torque,
            mass_scale: &m.inverse_mass_scale,
            inertia_scale: &m.inverse_inertia_scale,
        }
    }
}

/// Monomer `i`'s force, damping force and torque from the per-contact results (`pair_count`
/// of them its own) and the wall results (`wall_slots` per monomer, `wall_count` of them
/// `i`'s).
fn gather(
    i: usize,
    workspace: &Workspace,
    pair_count: u32,
    wall_slots: usize,
    wall_count: u32,
) -> (DVec3, DVec3, DVec3) {
    let incoming = &workspace.incoming;
    let owner_start = incoming.owner_start();
    let results = &workspace.pair_result;
    let (mut f, mut fd, mut t) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for idx in incoming.of(i) {
        let r = &results[idx as usize];
        f -= r.force;
        fd -= r.damping;
        t += r.torque_partner;
    }
    let own = owner_start[i] as usize;
    for r in &results[own..own + pair_count as usize] {
        f += r.force;
        fd += r.damping;
        t += r.torque_owner;
    }
    let ws = wall_slots;
    for r in &workspace.wall_result[i * ws..i * ws + wall_count as usize] {
        f += r.force;
        fd += r.damping;
        t += r.torque;
    }
    (f, fd, t)
}

/// The force (and its damping part) each wall exerts at this step: the blocks of
/// `wall_forces` added in order. Then the walls' share of the step's work by the trapezoid
/// rule, ½ (F_w(n) + F_w(n+1))·v_w dt, with the forces of the step before: the wall work, and
/// the damping against the walls, which joins the monomers' damping work in the tally.
#[allow(clippy::too_many_arguments)]
pub fn reduce_walls_final(
    dt: f64,
    walls: &[Wall],
    workspace: &Workspace,
    wall_force: &mut [DVec3],
    wall_damping: &mut [DVec3],
    tally: &mut Dissipation,
    wall_work: &mut f64,
) {
    let force = reduce_walls_final_from(&workspace.wall_partials, walls.len());
    let damping = reduce_walls_final_from(&workspace.wall_damping_partials, walls.len());
    let mut damping_work = workspace.damping_work;
    for (w, wall) in walls.iter().enumerate() {
        let travel = wall.velocity * dt;
        damping_work -= 0.5 * (wall_damping[w] + damping[w]).dot(travel);
        *wall_work += 0.5 * (wall_force[w] + force[w]).dot(travel);
    }
    tally.damping -= damping_work;
    wall_force.copy_from_slice(&force);
    wall_damping.copy_from_slice(&damping);
}
