//! The force pass's contact law four contacts at a time ([`ContactLanes`]): the lane twin of
//! `pair_geometry` and `pair_interaction_at` (state/interaction.rs) and of
//! `jkr_contact_radius_ratio` (model/normal.rs).
//!
//! Each lane does the operations of the scalar code for its contact in the same order
//! (lanes/four.rs), and the JKR inversion's Newton iterations are masked: a lane that has converged
//! (or stalled, or started below the branch end) keeps its value while the others iterate, so
//! it stops after the same iteration as the scalar loop would. The results are the scalar
//! code's to the bit, hence the GPU exact mode's; the tests hold them to that on contacts that
//! need from zero to many iterations.

use super::results::{OwnerChunk, PairResult, ResultPlaces};
use crate::backend::cpu::lanes::{in_lanes, ContactLanes, Isa, F4, M4, V4};
use crate::model::damping::Damping;
use crate::model::normal::{jkr_contact_radius_ratio, D_MIN, X_MIN, Y_MIN};
use crate::model::ContactLaw;
use crate::state::interaction::pair_interaction;
use crate::state::{Monomers, PairContact};
use glam::DVec3;

/// The force pass's chunk: it reads the rows.
pub type ForceChunk<'a> = OwnerChunk<'a, &'a [PairContact]>;

/// The contacts of one chunk of owners into their places in `results`, `lanes` wide.
pub fn chunk_forces(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    chunk: ForceChunk,
    results: ResultPlaces,
) {
    in_lanes!(
        lanes,
        chunk_in_lanes(law, m, chunk, results)
            as (law: &ContactLaw, m: &Monomers, chunk: ForceChunk, results: ResultPlaces),
        scalar => chunk_scalar(law, m, chunk, results),
    )
}

/// One contact at a time: the reference the lanes are held to.
fn chunk_scalar(law: &ContactLaw, m: &Monomers, chunk: ForceChunk, results: ResultPlaces) {
    let mut next = 0;
    for k in 0..chunk.counts.len() {
        chunk.prefetch_ahead(m, k, false);
        let at = results.owner(k, next);
        for (local, c) in chunk.rows[chunk.contacts_of(k)].iter().enumerate() {
            results.results[at + local] = scalar_result(law, m, chunk.first + k, c);
            next += 1;
        }
    }
}

pub(crate) fn scalar_result(
    law: &ContactLaw,
    m: &Monomers,
    i: usize,
    c: &PairContact,
) -> PairResult {
    let j = c.partner as usize;
    let (p, v) = (&m.position, &m.velocity);
    result_at(law, [p[i], p[j]], [v[i], v[j]], c)
}

/// What contact `c` exerts with its monomers at `x` and moving at `v` (owner, partner).
#[inline]
pub(super) fn result_at(
    law: &ContactLaw,
    [x1, x2]: [DVec3; 2],
    [v1, v2]: [DVec3; 2],
    c: &PairContact,
) -> PairResult {
    let (force, damping, torque_owner, torque_partner) = pair_interaction(law, x1, x2, v1, v2, c);
    PairResult {
        force,
        damping,
        torque_owner,
        torque_partner,
    }
}

/// The chunk's contacts in batches of four; a last batch of fewer goes one at a time.
#[inline(always)]
fn chunk_in_lanes<S: Isa>(
    law: &ContactLaw,
    m: &Monomers,
    chunk: ForceChunk,
    results: ResultPlaces,
) {
    let rows = chunk.rows;
    let mut owner = [0usize; 4];
    let mut slot = [0usize; 4];
    let mut place = [0usize; 4];
    let (mut filled, mut next) = (0, 0);
    for k in 0..chunk.counts.len() {
        chunk.prefetch_ahead(m, k, false);
        let at = results.owner(k, next);
        for (local, s) in chunk.contacts_of(k).enumerate() {
            owner[filled] = chunk.first + k;
            slot[filled] = s;
            place[filled] = at + local;
            filled += 1;
            next += 1;
            if filled == 4 {
                four_results::<S>(law, m, rows, &owner, &slot, (results.results, &place));
                filled = 0;
            }
        }
    }
    for l in 0..filled {
        results.results[place[l]] = scalar_result(law, m, owner[l], &rows[slot[l]]);
    }
}

#[inline(always)]
fn four_results<S: Isa>(
    law: &ContactLaw,
    m: &Monomers,
    rows: &[PairContact],
    owner: &[usize; 4],
    slot: &[usize; 4],
    out: (&mut [PairResult], &[usize; 4]),
) {
    let (p, v) = (&m.position, &m.velocity);
    let c = [
        &rows[slot[0]],
        &rows[slot[1]],
        &rows[slot[2]],
        &rows[slot[3]],
    ];
    let partner = |l: usize| c[l].partner as usize;
    let x1 = V4::<S>::gather(|l| p[owner[l]]);
    let x2 = V4::<S>::gather(|l| p[partner(l)]);
    let v1 = V4::<S>::gather(|l| v[owner[l]]);
    let v2 = V4::<S>::gather(|l| v[partner(l)]);
    results_of_four(law, [x1, x2], [v1, v2], pointers_of(c), out);
}

/// The pointers and twist of four contacts, in lanes.
#[inline(always)]
pub(super) fn pointers_of<S: Isa>(c: [&PairContact; 4]) -> ([V4<S>; 2], F4<S>) {
    let n1 = V4::<S>::gather(|l| c[l].n1);
    let n2 = V4::<S>::gather(|l| c[l].n2);
    let twist = F4::<S>::new([c[0].twist, c[1].twist, c[2].twist, c[3].twist]);
    ([n1, n2], twist)
}

/// What four contacts with pointers `n` and twist `twist` exert with their monomers at `x`
/// and moving at `v` (owners, partners), each into its place (`out`: the results and the four
/// places). Returns the tangential part it evaluated and the relative velocity: what the
/// contacts' step energies need besides the spins and the twist (booking_lanes.rs).
#[inline(always)]
pub(super) fn results_of_four<S: Isa>(
    law: &ContactLaw,
    [x1, x2]: [V4<S>; 2],
    [v1, v2]: [V4<S>; 2],
    ([n1, n2], twist): ([V4<S>; 2], F4<S>),
    (out, place): (&mut [PairResult], &[usize; 4]),
) -> (TangentialLanes<S>, V4<S>) {
    let g = pair_geometry_lanes(law, x1, x2, v1, v2);
    let (t, force) = pair_interaction_at_lanes(law, &g, n1, n2, twist);
    for (l, &p) in place.iter().enumerate() {
        out[p] = PairResult {
            force: force.lane(l),
            damping: g.damping.lane(l),
            torque_owner: t.torque1.lane(l),
            torque_partner: t.torque2.lane(l),
        };
    }
    (t, g.v_rel)
}

/// `PairGeometry` of four contacts.
pub(crate) struct PairGeometryLanes<S: Isa> {
    pub distance: F4<S>,
    pub nc: V4<S>,
    pub normal: V4<S>,
    pub damping: V4<S>,
    pub v_rel: V4<S>,
}

/// Lane twin of `pair_geometry`.
#[inline(always)]
pub(crate) fn pair_geometry_lanes<S: Isa>(
    law: &ContactLaw,
    x1: V4<S>,
    x2: V4<S>,
    v1: V4<S>,
    v2: V4<S>,
) -> PairGeometryLanes<S> {
    let k = &law.pair;
    let r = law.radius;
    let d = x1 - x2;
    let distance = d.length();
    let nc = d.divide(distance);
    let overlap_ratio = (2.0 * r - distance) / k.delta0;
    let x = jkr_contact_radius_ratio_lanes(overlap_ratio);
    let normal = nc.scale(jkr_force_lanes(x, k.f_c));
    let v_rel = v1 - v2;
    let coefficient = damping_coefficient_lanes(law, x * k.a0);
    let damping = nc.scale(-coefficient * v_rel.dot(nc));
    PairGeometryLanes {
        distance,
        nc,
        normal,
        damping,
        v_rel,
    }
}

/// Lane twin of `damping_coefficient` (the damping law is the same for every lane).
#[inline(always)]
fn damping_coefficient_lanes<S: Isa>(law: &ContactLaw, a: F4<S>) -> F4<S> {
    match law.damping {
        Damping::None => F4::<S>::splat(0.0),
        Damping::Viscous { kappa } => F4::<S>::splat(kappa),
        Damping::Viscoelastic { t_vis } => {
            2.0 * law.e_star * t_vis * a / (law.poisson * law.poisson)
        }
    }
}

/// Lane twin of `jkr_force`.
#[inline(always)]
fn jkr_force_lanes<S: Isa>(x: F4<S>, f_c: f64) -> F4<S> {
    4.0 * f_c * (x * x * x - x * x.sqrt())
}

/// Lane twin of `pair_interaction_at`: the tangential part (with the torques on 1 and 2) and
/// the force on 1 (its damping part is `g.damping`).
#[inline(always)]
pub(crate) fn pair_interaction_at_lanes<S: Isa>(
    law: &ContactLaw,
    g: &PairGeometryLanes<S>,
    n1: V4<S>,
    n2: V4<S>,
    twist: F4<S>,
) -> (TangentialLanes<S>, V4<S>) {
    let t = pair_tangential_lanes(law, g.nc, g.distance, n1, n2, twist);
    let force = g.normal + g.damping + t.slide;
    (t, force)
}

/// The rolling, sliding and twisting part of four contacts' interaction, with the
/// displacements it was made from.
pub(crate) struct TangentialLanes<S: Isa> {
    pub slide: V4<S>,
    pub torque1: V4<S>,
    pub torque2: V4<S>,
    pub xi: V4<S>,
    pub zeta: V4<S>,
}

/// Lane twin of `pair_tangential` (state/interaction.rs).
#[inline(always)]
pub(crate) fn pair_tangential_lanes<S: Isa>(
    law: &ContactLaw,
    nc: V4<S>,
    distance: F4<S>,
    n1: V4<S>,
    n2: V4<S>,
    twist: F4<S>,
) -> TangentialLanes<S> {
    let k = &law.pair;
    let r = law.radius;
    // rolling_displacement, sliding_displacement, sliding_force, twisting_torque
    let xi = (n1 + n2).times(k.reduced_radius);
    let p = n1.times(r) - n2.times(r);
    let zeta = p - nc.scale(p.dot(nc));
    let slide = zeta
        .times(-k.k_s)
        .scale((n2.times(r) - n1.times(r)).dot(nc) / distance);
    let twist_torque = nc.scale(-k.k_t * twist);
    // rolling_torque and sliding_torque (sign +1 for 1, −1 for 2)
    let rolling = -k.reduced_radius * k.k_r;
    // −sign·r·k_s with sign ±1: (−1)·r and 1·r are −r and r exactly.
    let sliding_1 = -r * k.k_s;
    let sliding_2 = r * k.k_s;
    let torque1 = n1.cross(xi).times(rolling) + n1.cross(zeta).times(sliding_1) + twist_torque;
    let torque2 = n2.cross(xi).times(rolling) + n2.cross(zeta).times(sliding_2) - twist_torque;
    TangentialLanes {
        slide,
        torque1,
        torque2,
        xi,
        zeta,
    }
}

/// `jkr_contact_radius_ratio` of each overlap ratio in `d`, in place, `lanes` wide (a last
/// batch of fewer than four one at a time): the same bits as one at a time.
pub fn radius_ratios(lanes: ContactLanes, d: &mut [f64]) {
    in_lanes!(
        lanes,
        radius_ratios_in_lanes(d) as (d: &mut [f64]),
        scalar => d.iter_mut().for_each(|d| *d = jkr_contact_radius_ratio(*d)),
    )
}

#[inline(always)]
fn radius_ratios_in_lanes<S: Isa>(d: &mut [f64]) {
    let mut fours = d.chunks_exact_mut(4);
    for four in &mut fours {
        let x = jkr_contact_radius_ratio_lanes(F4::<S>::new([four[0], four[1], four[2], four[3]]));
        four.copy_from_slice(&x.0);
    }
    for d in fours.into_remainder() {
        *d = jkr_contact_radius_ratio(*d);
    }
}

/// Lane twin of `jkr_contact_radius_ratio`: Newton's method on every lane at once, each lane
/// stopping where the scalar loop would (its value then held by the mask).
#[inline(always)]
pub(crate) fn jkr_contact_radius_ratio_lanes<S: Isa>(d: F4<S>) -> F4<S> {
    let below = d.le(F4::<S>::splat(D_MIN));
    let mut y = newton_start_lanes(d);
    let mut active = M4::ALL.and_not(below);
    for _ in 0..100 {
        if !active.any() {
            break;
        }
        let y3 = y * y * y;
        let g = 3.0 * y3 * y - 2.0 * y - d;
        let slope = 12.0 * y3 - 2.0;
        let step = g / slope;
        let next = (y - step).max(Y_MIN);
        let moving = active.and_not(next.ge(y));
        y = moving.select(next, y);
        active = moving.and_not(step.le(1e-15 * y));
    }
    below.select(F4::<S>::splat(X_MIN), y * y)
}

/// Lane twin of `newton_start`: both branches, each lane taking its own.
#[inline(always)]
fn newton_start_lanes<S: Isa>(d: F4<S>) -> F4<S> {
    let far = (d + 2.0).sqrt().sqrt().max(1.0);
    let above = 1.0 + ((100.0 + 72.0 * (d - 1.0)).sqrt() - 10.0) / 36.0;
    let beneath = 1.0 + (d - 1.0) / 10.0;
    let near = d.ge(F4::<S>::splat(1.0)).select(above, beneath);
    far.min(near)
}
