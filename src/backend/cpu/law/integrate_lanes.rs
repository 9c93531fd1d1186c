//! `integrate_pairs`' per-contact step: one contact at a time ([`integrate_pair_contact`],
//! with its tests, [`test_pair_contact`]) and four at a time, the lane twin of
//! `integrate_pair_contact`, of `rotate_pointer` (model/pointer.rs) and of the tests
//! `test_pair_contact` and `beyond_limits` make (state/interaction.rs).
//!
//! As in forces_lanes.rs, each lane does its contact's scalar operations in the scalar order
//! (lanes/four.rs), so pointers, twist and tests are the scalar code's bits; a pointer whose
//! monomer does not spin is kept as it is, as the scalar code returns it.
//!
//! The step's form (`integrate_pairs_step`, passes/integrate.rs, [`StepForm`]) also applies the
//! inelastic corrections of each contact beyond a limit that does not break, here, where its
//! pointers, positions and velocities are in the lanes already; the contacts pass would apply
//! the same corrections to the same values after the drift (corrections_lanes.rs). Then it
//! evaluates each contact's force on those values (`results_of_four`, forces_lanes.rs), as
//! the forces pass would after the events.

use super::booking_lanes::{correct_and_book_four, Advanced};
use super::corrections_lanes::{Found, Noted};
use super::forces_lanes::{pointers_of, result_at, results_of_four};
use super::limits_lanes::{limits_lanes, LimitsLanes};
use super::results::{OwnerChunk, PairResult, ResultPlaces};
use super::step_energy_lanes::Frame;
use crate::backend::cpu::lanes::{in_lanes, ContactLanes, Isa, F4, M4, V4};
use crate::backend::script::{PAIR_TEST_BEYOND, PAIR_TEST_BREAKS};
use crate::model::pointer::rotate_pointer;
use crate::model::twisting::twist_increment;
use crate::model::ContactLaw;
use crate::state::interaction::{beyond_limits, pair_frame};
use crate::state::{Dissipation, Monomers, PairContact};
use glam::DVec3;

/// One pair contact of owner `i` through `integrate_pairs`: the twist integral and both
/// pointers advanced, then its tests ([`test_pair_contact`]).
#[inline]
pub fn integrate_pair_contact(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    i: usize,
    c: &mut PairContact,
) -> u32 {
    let (pos, vel, omega) = (&m.position, &m.velocity, &m.angular_velocity);
    let j = c.partner as usize;
    // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
    let nc_mid = ((pos[i] - pos[j]) + (vel[i] - vel[j]) * (0.5 * dt)).normalize();
    c.twist += twist_increment(omega[i] - omega[j], nc_mid, dt);
    c.n1 = rotate_pointer(c.n1, omega[i] * dt);
    c.n2 = rotate_pointer(c.n2, omega[j] * dt);
    test_pair_contact(law, pos[i] + vel[i] * dt, pos[j] + vel[j] * dt, c)
}

/// What `contacts_scan` needs to know of one pair contact, at the positions, pointers and twist
/// the contact events will see: whether it breaks (δ < −δ_c, as the events test it) and whether
/// it is beyond an inelastic limit ([`PAIR_TEST_BREAKS`], [`PAIR_TEST_BEYOND`]).
#[inline]
pub fn test_pair_contact(law: &ContactLaw, x1: DVec3, x2: DVec3, c: &PairContact) -> u32 {
    let delta = 2.0 * law.radius - (x1 - x2).length();
    let breaks = if delta < -law.pair.delta_c {
        PAIR_TEST_BREAKS
    } else {
        0
    };
    let beyond = if beyond_limits(law, x1, x2, c) {
        PAIR_TEST_BEYOND
    } else {
        0
    };
    breaks | beyond
}

/// `integrate_pairs`' chunk of owners: it advances the rows in place.
pub type PairChunk<'a> = OwnerChunk<'a, &'a mut [PairContact]>;

/// What the step's form of the pass does besides advancing and testing: the corrections
/// (their states noted for the booking) and, where `results` is given, each contact's
/// force at the step's new positions into its place (where `forces` would put it after the
/// events).
pub struct StepForm<'a> {
    pub noted: &'a mut Noted,
    pub results: Option<ResultPlaces<'a>>,
    /// Where the forces are evaluated, the chunk's tally: the corrections of each four
    /// contacts are booked into it in the lanes as they are made (booking_lanes.rs), and only
    /// a last batch of fewer than four is noted for [`Noted::book`], which books it after them.
    pub booked: Option<&'a mut Dissipation>,
}

impl StepForm<'_> {
    /// Owner `k`'s first place (see [`ResultPlaces::owner`]).
    #[inline(always)]
    fn owner(&self, k: usize, next: usize) -> usize {
        self.results.as_ref().map_or(0, |r| r.owner(k, next))
    }

    #[inline(always)]
    fn put(&mut self, place: usize, result: PairResult) {
        if let Some(r) = self.results.as_mut() {
            r.results[place] = result;
        }
    }
}

/// The chunk's pair contacts advanced and tested, `lanes` wide; `tests[k]` gets owner k's
/// tests. With `step`, each contact beyond a limit that does not break is corrected too,
/// its states noted for the booking, no test says beyond, and the forces are evaluated where
/// it asks for them.
pub fn chunk_pairs(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    chunk: PairChunk,
    tests: &mut [u32],
    step: Option<StepForm>,
) {
    in_lanes!(
        lanes,
        chunk_in_lanes(law, dt, m, chunk, tests, step)
            as (
                law: &ContactLaw,
                dt: f64,
                m: &Monomers,
                chunk: PairChunk,
                tests: &mut [u32],
                step: Option<StepForm>,
            ),
        scalar => chunk_scalar(law, dt, m, chunk, tests, step),
    )
}

/// The step form's notes and whether it evaluates the forces.
fn parts<'s>(step: &'s mut Option<StepForm>) -> (Option<&'s mut Noted>, bool) {
    match step {
        None => (None, false),
        Some(form) => (Some(&mut *form.noted), form.results.is_some()),
    }
}

/// Four contacts' part of the step form: its notes and, where it evaluates the forces, the
/// results with the contacts' four places.
type FourForm<'s> = (
    Option<&'s mut Noted>,
    Option<(&'s mut [PairResult], &'s [usize; 4])>,
    Option<&'s mut Dissipation>,
);

fn parts_of_four<'s>(step: &'s mut Option<StepForm>, place: &'s [usize; 4]) -> FourForm<'s> {
    match step {
        None => (None, None, None),
        Some(form) => (
            Some(&mut *form.noted),
            form.results.as_mut().map(|r| (&mut *r.results, place)),
            form.booked.as_deref_mut(),
        ),
    }
}

fn chunk_scalar(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    chunk: PairChunk,
    tests: &mut [u32],
    mut step: Option<StepForm>,
) {
    let mut next = 0;
    for (k, test) in tests.iter_mut().enumerate() {
        chunk.prefetch_ahead(m, k, true);
        let at = step.as_ref().map_or(0, |f| f.owner(k, next));
        let mut bits = 0;
        for (local, s) in chunk.contacts_of(k).enumerate() {
            let (i, c) = (chunk.first + k, &mut chunk.rows[s]);
            let (tests, force) = one_contact(law, dt, m, i, c, parts(&mut step));
            bits |= tests;
            if let (Some(form), Some(force)) = (step.as_mut(), force) {
                form.put(at + local, force);
            }
            next += 1;
        }
        *test = bits;
    }
}

/// One contact of owner `i` advanced and tested the scalar way, corrected where `noted`;
/// its tests, and its force where `evaluated`.
fn one_contact(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    i: usize,
    c: &mut PairContact,
    (noted, evaluated): (Option<&mut Noted>, bool),
) -> (u32, Option<PairResult>) {
    let tested = integrate_pair_contact(law, dt, m, i, c);
    let bits = match noted {
        Some(noted) => correct_one(law, dt, m, i, c, tested, noted),
        None => tested,
    };
    let force = evaluated.then(|| {
        let (p, v, j) = (&m.position, &m.velocity, c.partner as usize);
        let x = [p[i] + v[i] * dt, p[j] + v[j] * dt];
        result_at(law, x, [v[i], v[j]], c)
    });
    (bits, force)
}

/// Whether a contact's tests ask for its corrections now: beyond a limit, not breaking (a
/// breaking contact leaves the table in the contacts pass, uncorrected).
fn corrected_now(tests: u32) -> bool {
    tests & PAIR_TEST_BEYOND != 0 && tests & PAIR_TEST_BREAKS == 0
}

/// One contact's corrections, where its `tests` ask for them, at the positions the drift is
/// about to store; returns its tests as the contacts scan should see them: none beyond a limit
/// (a breaking contact leaves the table uncorrected, and an owner listed for corrections would
/// have the others corrected twice).
fn correct_one(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    i: usize,
    c: &mut PairContact,
    tests: u32,
    noted: &mut Noted,
) -> u32 {
    if !corrected_now(tests) {
        return tests & !PAIR_TEST_BEYOND;
    }
    let (p, v) = (&m.position, &m.velocity);
    let j = c.partner as usize;
    let (x1, x2) = (p[i] + v[i] * dt, p[j] + v[j] * dt);
    let found = Found::at(law, x1, x2, c);
    noted.apply(law, i, c, found, || pair_frame(x1, x2, v[i], v[j]));
    tests & !PAIR_TEST_BEYOND
}

/// The chunk's contacts in batches of four across owners; a last batch of fewer goes one at a
/// time.
#[inline(always)]
fn chunk_in_lanes<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    chunk: PairChunk,
    tests: &mut [u32],
    mut step: Option<StepForm>,
) {
    let mut owner = [0usize; 4];
    let mut slot = [0usize; 4];
    let mut place = [0usize; 4];
    let (mut filled, mut next) = (0, 0);
    for k in 0..tests.len() {
        chunk.prefetch_ahead(m, k, true);
        tests[k] = 0;
        let at = step.as_ref().map_or(0, |f| f.owner(k, next));
        for (local, s) in chunk.contacts_of(k).enumerate() {
            owner[filled] = k;
            slot[filled] = s;
            place[filled] = at + local;
            filled += 1;
            next += 1;
            if filled == 4 {
                let at = Four {
                    rows: &mut *chunk.rows,
                    first: chunk.first,
                    owner: &owner,
                    slot: &slot,
                };
                let bits = four_pairs::<S>(law, dt, m, at, parts_of_four(&mut step, &place));
                for l in 0..4 {
                    tests[owner[l]] |= bits[l];
                }
                filled = 0;
            }
        }
    }
    for l in 0..filled {
        let (i, c) = (chunk.first + owner[l], &mut chunk.rows[slot[l]]);
        let (bits, force) = one_contact(law, dt, m, i, c, parts(&mut step));
        tests[owner[l]] |= bits;
        if let (Some(form), Some(force)) = (step.as_mut(), force) {
            form.put(place[l], force);
        }
    }
}

/// Four contacts of a chunk: owners `first + owner[l]`, in slots `slot[l]` of `rows`.
struct Four<'a> {
    rows: &'a mut [PairContact],
    first: usize,
    owner: &'a [usize; 4],
    slot: &'a [usize; 4],
}

/// Four contacts advanced in place, corrected where `noted` and their tests ask for it; their
/// tests, and their forces where `evaluated`.
#[inline(always)]
fn four_pairs<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    four: Four,
    (noted, mut out, booked): FourForm,
) -> [u32; 4] {
    let Four {
        rows,
        first,
        owner,
        slot,
    } = four;
    let (pos, vel, omega) = (&m.position, &m.velocity, &m.angular_velocity);
    let i = |l: usize| first + owner[l];
    let j = |l: usize| rows[slot[l]].partner as usize;
    let (x1, x2) = (
        V4::<S>::gather(|l| pos[i(l)]),
        V4::<S>::gather(|l| pos[j(l)]),
    );
    let (v1, v2) = (
        V4::<S>::gather(|l| vel[i(l)]),
        V4::<S>::gather(|l| vel[j(l)]),
    );
    let (w1, w2) = (
        V4::<S>::gather(|l| omega[i(l)]),
        V4::<S>::gather(|l| omega[j(l)]),
    );
    let n1 = V4::<S>::gather(|l| rows[slot[l]].n1);
    let n2 = V4::<S>::gather(|l| rows[slot[l]].n2);
    let twist = F4::<S>::new(slot.map(|s| rows[s].twist));
    // integrate_pair_contact, twist_increment
    let nc_mid = ((x1 - x2) + (v1 - v2).times(0.5 * dt)).normalize();
    let twist = twist + (w1 - w2).dot(nc_mid) * dt;
    let n1 = rotate_pointer_lanes(n1, w1.times(dt));
    let n2 = rotate_pointer_lanes(n2, w2.times(dt));
    let (x1, x2) = (x1 + v1.times(dt), x2 + v2.times(dt));
    let (bits, nc) = test_pair_contact_lanes(law, x1, x2, n1, n2, twist);
    for (l, &s) in slot.iter().enumerate() {
        let c = &mut rows[s];
        c.twist = twist.0[l];
        c.n1 = n1.lane(l);
        c.n2 = n2.lane(l);
    }
    let Some(noted) = noted else {
        return bits;
    };
    if let (Some(out), Some(tally)) = (out.as_mut(), booked) {
        let advanced = Advanced {
            x: [x1, x2],
            v: [v1, v2],
            w: [w1, w2],
            n: [n1, n2],
            nc,
            twist,
        };
        let corrected = bits.map(corrected_now);
        let out = (&mut *out.0, out.1);
        correct_and_book_four(law, dt, (rows, slot), &advanced, corrected, out, tally);
        return bits.map(|b| b & !PAIR_TEST_BEYOND);
    }
    let at = Four {
        rows: &mut *rows,
        first,
        owner,
        slot,
    };
    correct_four(law, at, [x1, x2, v1, v2], [n1, n2, nc], bits, noted);
    // Not in a closure: one would be compiled apart from the lanes' AVX2 code.
    if let Some(out) = out {
        let pointers = if bits.iter().any(|&b| corrected_now(b)) {
            pointers_of([
                &rows[slot[0]],
                &rows[slot[1]],
                &rows[slot[2]],
                &rows[slot[3]],
            ])
        } else {
            ([n1, n2], twist)
        };
        results_of_four(law, [x1, x2], [v1, v2], pointers, out);
    }
    // The scan lists no owner for corrections after these (see `correct_one`).
    bits.map(|b| b & !PAIR_TEST_BEYOND)
}

/// The corrections of those of four contacts whose `bits` ask for them, with their monomers
/// at `x1`, `x2` moving at `v1`, `v2`, their advanced pointers `n1`, `n2` and normals `nc`.
#[inline(always)]
fn correct_four<S: Isa>(
    law: &ContactLaw,
    four: Four,
    [x1, x2, v1, v2]: [V4<S>; 4],
    [n1, n2, nc]: [V4<S>; 3],
    bits: [u32; 4],
    noted: &mut Noted,
) {
    if !bits.iter().any(|&b| corrected_now(b)) {
        return;
    }
    let Four {
        rows,
        first,
        owner,
        slot,
    } = four;
    // Corrections::found of the twin (corrections_lanes.rs) on the same values: the rolling
    // correction, then the sliding one on the pointers it left.
    let LimitsLanes {
        rolled,
        rolled_n: [rolled_n1, rolled_n2],
        slid,
        slid_n: [slid_n1, slid_n2],
        ..
    } = limits_lanes(law, [n1, n2], nc);
    let frames = Frame::of(x1, x2, v1, v2);
    let set = |mask: M4<S>, l: usize| mask.0[l] != 0;
    for l in (0..4).filter(|&l| corrected_now(bits[l])) {
        let found = Found {
            rolled: set(rolled, l).then(|| (rolled_n1.lane(l), rolled_n2.lane(l))),
            slid: set(slid, l).then(|| (slid_n1.lane(l), slid_n2.lane(l))),
        };
        noted.apply(law, first + owner[l], &mut rows[slot[l]], found, || {
            frames.lane(l)
        });
    }
}

/// Lane twin of `test_pair_contact` and `beyond_limits`: the lengths in lanes, the
/// comparisons lane by lane as the scalar code makes them; with the contact normals.
#[inline(always)]
fn test_pair_contact_lanes<S: Isa>(
    law: &ContactLaw,
    x1: V4<S>,
    x2: V4<S>,
    n1: V4<S>,
    n2: V4<S>,
    twist: F4<S>,
) -> ([u32; 4], V4<S>) {
    let k = &law.pair;
    let r = law.radius;
    let delta = 2.0 * r - (x1 - x2).length();
    let nc = (x1 - x2).normalize();
    let rolling = (n1 + n2).length() * k.reduced_radius;
    let p = n1.times(r) - n2.times(r);
    let sliding = (p - nc.scale(p.dot(nc))).length();
    // `!(x <= limit)`: a NaN displacement counts as beyond, as in `beyond_limits`.
    let beyond = |x: f64, limit: f64| {
        use std::cmp::Ordering::{Equal, Less};
        !matches!(x.partial_cmp(&limit), Some(Less | Equal))
    };
    let bits = std::array::from_fn(|l| {
        let breaks = delta.0[l] < -k.delta_c;
        let beyond = beyond(rolling.0[l], k.xi_crit)
            || beyond(sliding.0[l], k.zeta_crit)
            || twist.0[l].abs() > k.phi_crit;
        (if breaks { PAIR_TEST_BREAKS } else { 0 }) | (if beyond { PAIR_TEST_BEYOND } else { 0 })
    });
    (bits, nc)
}

/// Lane twin of `rotate_pointer`: the same polynomials in θ², the same grouping.
#[inline(always)]
pub(crate) fn rotate_pointer_lanes<S: Isa>(n: V4<S>, w: V4<S>) -> V4<S> {
    let t2 = w.dot(w);
    let sinc = 1.0
        - t2 * 0.16666666666666666
            * (1.0
                - t2 * 0.05
                    * (1.0
                        - t2 * 0.023809523809523808
                            * (1.0
                                - t2 * 0.013888888888888888 * (1.0 - t2 * 0.00909090909090909))));
    let cosc = 0.5
        * (1.0
            - t2 * 0.08333333333333333
                * (1.0
                    - t2 * 0.03333333333333333
                        * (1.0 - t2 * 0.017857142857142856 * (1.0 - t2 * 0.011111111111111112))));
    let cos = 1.0 - t2 * cosc;
    let rotated = n.scale(cos) + w.cross(n).scale(sinc) + w.scale(w.dot(n) * cosc);
    V4::select(t2.eq(F4::<S>::splat(0.0)), n, rotated.normalize())
}
