//! Leap-frog pass: kick v(n−½) → v(n+½) with the forces at n, turn contact pointers and advance
//! twist integrals with the mid-step angular velocities, drift positions and walls.
//!
//! Every loop is per monomer (or per owner row) with no sums across monomers, so it runs in
//! parallel with the same bits for any thread count. The twins of the entry points of
//! shaders/passes/integrate.wgsl, one function each.

use super::neighbours::NeighbourList;
use super::prefetching::for_contact_passes;
use crate::backend::cpu::chunking::{split_at_offsets, split_len, sum_in_order, CHUNK};
use crate::backend::cpu::lanes::ContactLanes;
use crate::backend::cpu::law::corrections_lanes::Noted;
use crate::backend::cpu::law::integrate_lanes::{chunk_pairs, PairChunk, StepForm};
use crate::backend::cpu::law::results::{PairResult, ResultPlaces};
use crate::backend::cpu::workspace::Workspace;
use crate::model::pointer::rotate_pointer;
use crate::model::twisting::twist_increment;
use crate::model::ContactLaw;
use crate::state::{ContactTable, Dissipation, Monomers, Wall, WallContact};
use glam::DVec3;
use rayon::prelude::*;

/// Kick, and the wall contacts' pointers and twist, which need only the monomer's own
/// mid-step spin; clears the pair tests for this step's `integrate_pairs`. Parallel over
/// chunks of monomers, a plain loop within each.
pub fn integrate_kick(
    dt: f64,
    inverse_mass: f64,
    inverse_inertia: f64,
    monomers: &mut Monomers,
    table: &mut ContactTable,
    walls: &[Wall],
    pair_tests: &mut Vec<u32>,
) {
    pair_tests.clear();
    pair_tests.resize(monomers.len(), 0);
    let ws = table.wall_slots;
    let n = monomers.len();
    let m = monomers;
    let (force, torque) = (&m.force, &m.torque);
    let (mass_scale, inertia_scale) = (&m.inverse_mass_scale, &m.inverse_inertia_scale);
    let kick = NextKick {
        dt,
        inverse_mass,
        inverse_inertia,
    };
    (
        m.velocity.par_chunks_mut(CHUNK),
        m.angular_velocity.par_chunks_mut(CHUNK),
        table.wall.par_chunks_mut(CHUNK * ws),
        table.wall_count.par_chunks(CHUNK),
    )
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .for_each(|(chunk, (velocity, spin, wall_rows, counts))| {
            let first = chunk * CHUNK;
            for k in 0..velocity.len() {
                let i = first + k;
                let row = &mut wall_rows[k * ws..k * ws + counts[k] as usize];
                let scales = (mass_scale[i], inertia_scale[i]);
                kick.kick(
                    (force[i], torque[i]),
                    scales,
                    (&mut velocity[k], &mut spin[k]),
                    row,
                    walls,
                );
            }
        });
}

/// What the kick of one monomer needs besides the monomer: `integrate_kick`'s constants.
#[derive(Clone, Copy, Debug)]
pub struct NextKick {
    pub dt: f64,
    pub inverse_mass: f64,
    pub inverse_inertia: f64,
}

impl NextKick {
    /// One monomer's kick with its force and torque `(f, t)` and inverse mass and inertia
    /// scales: velocity and spin, then its wall contacts' twist and pointer with the new spin.
    #[inline(always)]
    pub fn kick(
        &self,
        (f, t): (DVec3, DVec3),
        (mass_scale, inertia_scale): (f64, f64),
        (velocity, spin): (&mut DVec3, &mut DVec3),
        wall_rows: &mut [WallContact],
        walls: &[Wall],
    ) {
        let dt = self.dt;
        *velocity += f * (dt * self.inverse_mass * mass_scale);
        *spin += t * (dt * self.inverse_inertia * inertia_scale);
        let omega = *spin;
        for c in wall_rows {
            c.twist += twist_increment(omega, walls[c.wall as usize].normal, dt);
            c.n1 = rotate_pointer(c.n1, omega * dt);
        }
    }
}

/// Both pointers and the twist integral of every pair contact, with the kicked velocities
/// and the positions before the drift; then the contact's tests for `contacts_scan`
/// ([`test_pair_contact`]) at the positions the drift is about to store. Parallel over chunks
/// of owners, the contacts of a chunk four at a time where the processor has vector lanes
/// (law/integrate_lanes.rs, the same bits).
pub fn integrate_pairs(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    pair_tests: &mut [u32],
) {
    pairs_pass(law, dt, monomers, table, pair_tests, None, None);
}

/// The CPU step's `integrate_pairs`: the same, and two things the device does later.
///
/// 1. Each pair contact beyond an inelastic limit that does not break is corrected now, its
///    dissipation added to `tally` (where booked), instead of in the contacts pass. The
///    corrections are the contacts pass's on the same values (the positions the drift stores,
///    the same pointers), so the state after the step has the same bits; the tally's sum
///    differs only in the order of one owner's corrections where a contact of it breaks (the
///    events reorder its slots). docs/guide/src/benchmarks.md, "CPU engine: the corrections
///    where the pointers are".
/// 2. Each contact's force at the positions the drift is about to store goes into
///    `workspace.pair_result`, where `forces` would put it (by the partner index, rebuilt
///    first where stale). The contacts pass then moves those results with the rows its events
///    leave alone, and the step's `forces` evaluates only the rows the events changed
///    (`forces_of_changed_rows`): the same values from the same operations, one sweep over
///    the contacts fewer. docs/guide/src/benchmarks.md, "CPU engine: the forces where the
///    pointers are".
pub fn integrate_pairs_step(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    workspace: &mut Workspace,
    tally: &mut Dissipation,
) {
    if !workspace.partner_index_current {
        workspace.incoming.rebuild(table);
        workspace.partner_index_current = true;
    }
    let index = &workspace.incoming;
    let (owner_start, bases) = (index.owner_start(), index.chunk_bases());
    let n = monomers.len();
    let results = &mut workspace.pair_result;
    results.resize(owner_start[n] as usize, PairResult::default());
    let stretches = split_at_offsets(results, bases.iter().map(|&b| b as usize));
    let places = stretches
        .into_iter()
        .enumerate()
        .map(|(chunk, results)| ResultPlaces {
            results,
            starts: Some(&owner_start[chunk * CHUNK..((chunk + 1) * CHUNK).min(n)]),
            base: bases[chunk],
        })
        .collect();
    let books = tally.books_pair_corrections();
    let tests = &mut workspace.pair_tests;
    let sums = pairs_pass(law, dt, monomers, table, tests, Some(books), Some(places));
    tally.add(&sum_in_order(&sums));
    workspace.results_of_step = true;
    workspace.changed_rows.clear();
}

/// Every form of the pairs pass, parallel over chunks of owners; with `correcting` (whether
/// the corrections are booked), each chunk's corrections and what they dissipated, one sum
/// per chunk in order, and with `results` (each chunk's places) the contacts' forces.
fn pairs_pass(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    table: &mut ContactTable,
    pair_tests: &mut [u32],
    correcting: Option<bool>,
    results: Option<Vec<ResultPlaces>>,
) -> Vec<Dissipation> {
    let slots = table.pair_slots;
    let prefetching = for_contact_passes(table);
    let lanes = ContactLanes::chosen();
    let chunks = monomers.len().div_ceil(CHUNK);
    let stretches: Vec<Option<ResultPlaces>> = match results {
        Some(r) => r.into_iter().map(Some).collect(),
        None => (0..chunks).map(|_| None).collect(),
    };
    (
        table.pair.par_chunks_mut(CHUNK * slots),
        table.pair_count.par_chunks(CHUNK),
        pair_tests.par_chunks_mut(CHUNK),
        stretches.into_par_iter(),
    )
        .into_par_iter()
        .with_min_len(split_len(monomers.len(), CHUNK))
        .enumerate()
        .map(|(chunk, (rows, counts, tests, results))| {
            let owners = PairChunk {
                rows,
                slots,
                counts,
                first: chunk * CHUNK,
                prefetching,
            };
            let mut dissipated = Dissipation::default();
            let Some(books) = correcting else {
                chunk_pairs(lanes, law, dt, monomers, owners, tests, None);
                return dissipated;
            };
            // Where the forces are evaluated, the lanes book as they go and note only a last
            // batch of fewer than four (the scalar lanes note everything).
            let in_lanes = books && results.is_some() && lanes != ContactLanes::Scalar;
            let contacts = match in_lanes {
                true => 3,
                false => counts.iter().map(|&c| c as usize).sum(),
            };
            let mut noted = Noted::with_room_for(contacts, books);
            let step = StepForm {
                noted: &mut noted,
                results,
                booked: in_lanes.then_some(&mut dissipated),
            };
            chunk_pairs(lanes, law, dt, monomers, owners, tests, Some(step));
            if books {
                noted.book(lanes, law, dt, monomers, &mut dissipated);
            }
            dissipated
        })
        .collect()
}

/// Positions and walls; whether some monomer has moved more than half the skin since the
/// candidate list was built (the list's `rebuild_due`, for the neighbour passes).
pub fn integrate_drift(
    dt: f64,
    monomers: &mut Monomers,
    walls: &mut [Wall],
    neighbours: &mut NeighbourList,
) {
    let velocity = &monomers.velocity;
    let limit = 0.25 * neighbours.skin * neighbours.skin;
    let reference = &neighbours.reference;
    let fresh = reference.len() == velocity.len();
    let moved = monomers
        .position
        .par_chunks_mut(CHUNK)
        .zip(velocity.par_chunks(CHUNK))
        .with_min_len(split_len(velocity.len(), CHUNK))
        .enumerate()
        .map(|(chunk, (x, v))| {
            let mut moved = false;
            for (k, (x, v)) in x.iter_mut().zip(v).enumerate() {
                *x += *v * dt;
                moved |= fresh && (*x - reference[chunk * CHUNK + k]).length_squared() > limit;
            }
            moved
        })
        .reduce(|| false, |a, b| a || b);
    neighbours.rebuild_due |= moved || !fresh;
    for w in walls.iter_mut() {
        w.point += w.velocity * dt;
    }
}

/// The half-step shift of synchronised initial velocities, v(−½) = v(0) − F(0) dt / 2m (and
/// the spins), as the leap-frog stores them.
pub fn integrate_start(dt: f64, inverse_mass: f64, inverse_inertia: f64, monomers: &mut Monomers) {
    let half = 0.5 * dt;
    let m = monomers;
    for i in 0..m.len() {
        m.velocity[i] -= m.force[i] * (half * inverse_mass * m.inverse_mass_scale[i]);
        m.angular_velocity[i] -=
            m.torque[i] * (half * inverse_inertia * m.inverse_inertia_scale[i]);
    }
}

/// After the forces at time 0: the damping and wall-work channels book work over a step, and
/// there is no step before time 0.
pub fn integrate_clear_work(tally: &mut Dissipation, wall_work: &mut f64) {
    tally.damping = 0.0;
    *wall_work = 0.0;
}
