//! The pair contacts' inelastic corrections of one chunk of owners, their step energies four
//! at a time: `apply_inelastic_limits` (forces.rs) split into its three parts.
//!
//! 1. Per contact, in order, the corrections change pointers and twist exactly as the scalar
//!    code does (they need no energy), and every state whose step energy the scalar code
//!    evaluates is noted: the contact before its first correction and after each one.
//! 2. Those step energies: first each corrected contact's geometry and JKR potential, four
//!    contacts at a time (the lane twins of `pair_geometry` and `pair_normal_potential`),
//!    shared between its states as the scalar code shares them; then the step energies,
//!    four states at a time (the lane twin of `pair_step_energy_at`).
//! 3. The drops booked channel by channel in the scalar order (owner, contact, rolling before
//!    sliding before twisting), so the tally is the scalar code's to the bit.
//!
//! In a compressed sample most contacts of a flagged owner roll or slide every step, and these
//! energies were most of the contacts pass (DESIGN.md, "The CPU engine on many cores").

use super::forces::apply_inelastic_limits;
use super::forces_lanes::{
    pair_geometry_lanes, pair_interaction_at_lanes, ContactLanes, PairGeometryLanes,
};
#[cfg(target_arch = "x86_64")]
use super::lanes::Avx2;
use super::lanes::{Isa, Portable, F4, V4};
use crate::model::normal::{jkr_force, D_MIN, X_AT_ZERO_OVERLAP, X_MIN};
use crate::model::{rolling, sliding, twisting, ContactLaw};
use crate::state::interaction::{
    pair_geometry, pair_normal_potential, pair_step_energy_at, PairGeometry,
};
use crate::state::{Dissipation, Monomers, PairContact};

/// One state whose step energy the booking needs: contact `contact` of the chunk's corrected
/// contacts as it stood then.
#[derive(Clone, Copy)]
struct EnergyOf {
    contact: usize,
    state: PairContact,
}

/// A corrected contact: owner and partner.
#[derive(Clone, Copy)]
struct Corrected {
    i: usize,
    j: usize,
}

/// What a corrected contact's states share, as `apply_inelastic_limits` shares it: the
/// geometry and its JKR potential.
#[derive(Clone, Copy)]
struct Shared {
    geometry: PairGeometry,
    normal_potential: f64,
}

/// Which corrections one contact had; its energies are `first..first + 1 + corrections`.
#[derive(Clone, Copy)]
struct Booking {
    first: usize,
    rolled: bool,
    slid: bool,
    twisted: bool,
}

/// The corrections of the owners `rows` lists (owner index, its contacts), `lanes` wide,
/// their dissipation added to `tally`.
pub fn chunk_corrections<'a>(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    rows: impl Iterator<Item = (usize, &'a mut [PairContact])>,
    tally: &mut Dissipation,
) {
    if lanes == ContactLanes::Scalar {
        for (i, contacts) in rows {
            for c in contacts {
                apply_inelastic_limits(law, m, dt, i, c, tally);
            }
        }
        return;
    }
    let mut states = vec![];
    let mut contacts = vec![];
    let mut bookings = vec![];
    for (i, row) in rows {
        for c in row {
            let contact = Corrected {
                i,
                j: c.partner as usize,
            };
            if let Some(b) = correct(law, m, contact, contacts.len(), c, &mut states) {
                contacts.push(contact);
                bookings.push(b);
            }
        }
    }
    let shared = shared_geometries(lanes, law, m, &contacts);
    let energies = step_energies(lanes, law, dt, m, &contacts, &shared, &states);
    for b in bookings {
        let mut e = energies[b.first..].iter();
        let mut before = *e.next().expect("the state before");
        let mut book = |channel: &mut f64| {
            let after = *e.next().expect("a state per correction");
            *channel += before - after;
            before = after;
        };
        if b.rolled {
            book(&mut tally.rolling);
        }
        if b.slid {
            book(&mut tally.sliding);
        }
        if b.twisted {
            book(&mut tally.twisting);
        }
    }
}

/// `apply_inelastic_limits` without the energies: the corrections applied to `c`, the states
/// to evaluate pushed on `states`; `None` where nothing was corrected.
fn correct(
    law: &ContactLaw,
    m: &Monomers,
    Corrected { i, j }: Corrected,
    contact: usize,
    c: &mut PairContact,
    states: &mut Vec<EnergyOf>,
) -> Option<Booking> {
    let k = &law.pair;
    let r = law.radius;
    let p = &m.position;
    let nc = (p[i] - p[j]).normalize();
    let first = states.len();
    let before = *c;
    let mut booking = Booking {
        first,
        rolled: false,
        slid: false,
        twisted: false,
    };
    // The state before the first correction, then the state after each.
    let corrected = |c: &PairContact, states: &mut Vec<EnergyOf>| {
        if states.len() == first {
            states.push(EnergyOf {
                contact,
                state: before,
            });
        }
        states.push(EnergyOf { contact, state: *c });
    };
    if let Some((n1, n2)) = rolling::rolling_correction(c.n1, c.n2, k.reduced_radius, k.xi_crit) {
        c.n1 = n1;
        c.n2 = n2;
        corrected(c, states);
        booking.rolled = true;
    }
    if let Some((n1, n2)) = sliding::sliding_correction(c.n1, c.n2, nc, r, r, k.zeta_crit) {
        c.n1 = n1;
        c.n2 = n2;
        corrected(c, states);
        booking.slid = true;
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
        c.twist = twist;
        corrected(c, states);
        booking.twisted = true;
    }
    (booking.rolled || booking.slid || booking.twisted).then_some(booking)
}

/// The geometry and JKR potential of every corrected contact, `lanes` wide; a last batch of
/// fewer than four goes through the scalar code.
fn shared_geometries(
    lanes: ContactLanes,
    law: &ContactLaw,
    m: &Monomers,
    contacts: &[Corrected],
) -> Vec<Shared> {
    let mut shared = Vec::with_capacity(contacts.len());
    let batches = contacts.len() / 4;
    match lanes {
        #[cfg(target_arch = "x86_64")]
        ContactLanes::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"));
            // SAFETY: the processor has AVX2 (checked above).
            unsafe { geometries_avx2(law, m, &contacts[..4 * batches], &mut shared) }
        }
        _ => geometries_in_lanes::<Portable>(law, m, &contacts[..4 * batches], &mut shared),
    }
    let (p, v) = (&m.position, &m.velocity);
    for &Corrected { i, j } in &contacts[4 * batches..] {
        let geometry = pair_geometry(law, p[i], p[j], v[i], v[j]);
        let normal_potential = pair_normal_potential(law, &geometry);
        shared.push(Shared {
            geometry,
            normal_potential,
        });
    }
    shared
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn geometries_avx2(
    law: &ContactLaw,
    m: &Monomers,
    contacts: &[Corrected],
    shared: &mut Vec<Shared>,
) {
    geometries_in_lanes::<Avx2>(law, m, contacts, shared)
}

#[inline(always)]
fn geometries_in_lanes<S: Isa>(
    law: &ContactLaw,
    m: &Monomers,
    contacts: &[Corrected],
    shared: &mut Vec<Shared>,
) {
    let (p, v) = (&m.position, &m.velocity);
    for four in contacts.chunks_exact(4) {
        let (i, j) = (|l: usize| four[l].i, |l: usize| four[l].j);
        let g = pair_geometry_lanes(
            law,
            V4::<S>::gather(|l| p[i(l)]),
            V4::<S>::gather(|l| p[j(l)]),
            V4::<S>::gather(|l| v[i(l)]),
            V4::<S>::gather(|l| v[j(l)]),
        );
        let normal = normal_potential_lanes(law, g.radius_ratio, g.overlap_ratio);
        shared.extend((0..4).map(|l| Shared {
            geometry: PairGeometry {
                distance: g.distance.0[l],
                overlap_ratio: g.overlap_ratio.0[l],
                radius_ratio: g.radius_ratio.0[l],
                nc: g.nc.lane(l),
                normal: g.normal.lane(l),
                damping: g.damping.lane(l),
                v_rel: g.v_rel.lane(l),
            },
            normal_potential: normal.0[l],
        }));
    }
}

/// The step energy of every noted state, in order, `lanes` wide, from its contact's shared
/// geometry; a last batch of fewer than four goes through the scalar code.
fn step_energies(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    contacts: &[Corrected],
    shared: &[Shared],
    states: &[EnergyOf],
) -> Vec<f64> {
    let mut energies = vec![0.0; states.len()];
    let batches = states.len() / 4;
    let at = Energies {
        law,
        dt,
        m,
        contacts,
        shared,
    };
    match lanes {
        #[cfg(target_arch = "x86_64")]
        ContactLanes::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"));
            // SAFETY: the processor has AVX2 (checked above).
            unsafe { energies_avx2(&at, &states[..4 * batches], &mut energies) }
        }
        _ => energies_in_lanes::<Portable>(&at, &states[..4 * batches], &mut energies),
    }
    let w = &m.angular_velocity;
    for (k, s) in states.iter().enumerate().skip(4 * batches) {
        let Corrected { i, j } = contacts[s.contact];
        let Shared {
            geometry,
            normal_potential,
        } = &shared[s.contact];
        energies[k] =
            pair_step_energy_at(law, geometry, *normal_potential, w[i], w[j], dt, &s.state);
    }
    energies
}

/// What the step energies of the noted states read.
struct Energies<'a> {
    law: &'a ContactLaw,
    dt: f64,
    m: &'a Monomers,
    contacts: &'a [Corrected],
    shared: &'a [Shared],
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn energies_avx2(at: &Energies, states: &[EnergyOf], energies: &mut [f64]) {
    energies_in_lanes::<Avx2>(at, states, energies)
}

#[inline(always)]
fn energies_in_lanes<S: Isa>(at: &Energies, states: &[EnergyOf], energies: &mut [f64]) {
    let w = &at.m.angular_velocity;
    for (four, out) in states.chunks_exact(4).zip(energies.chunks_exact_mut(4)) {
        let contact = |l: usize| at.contacts[four[l].contact];
        let shared = |l: usize| &at.shared[four[l].contact];
        let g = |l: usize| &shared(l).geometry;
        let geometry = PairGeometryLanes {
            distance: F4::<S>::new(std::array::from_fn(|l| g(l).distance)),
            overlap_ratio: F4::<S>::new(std::array::from_fn(|l| g(l).overlap_ratio)),
            radius_ratio: F4::<S>::new(std::array::from_fn(|l| g(l).radius_ratio)),
            nc: V4::<S>::gather(|l| g(l).nc),
            normal: V4::<S>::gather(|l| g(l).normal),
            damping: V4::<S>::gather(|l| g(l).damping),
            v_rel: V4::<S>::gather(|l| g(l).v_rel),
        };
        let e = step_energy_lanes(
            at.law,
            at.dt,
            &geometry,
            F4::<S>::new(std::array::from_fn(|l| shared(l).normal_potential)),
            [
                V4::<S>::gather(|l| w[contact(l).i]),
                V4::<S>::gather(|l| w[contact(l).j]),
            ],
            [
                V4::<S>::gather(|l| four[l].state.n1),
                V4::<S>::gather(|l| four[l].state.n2),
            ],
            F4::<S>::new(std::array::from_fn(|l| four[l].state.twist)),
        );
        out.copy_from_slice(&e.0);
    }
}

/// Lane twin of `pair_step_energy_at`: the contacts' geometry and JKR potential, the spins of
/// owner and partner, the pointers and the twist.
#[inline(always)]
fn step_energy_lanes<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    g: &PairGeometryLanes<S>,
    normal: F4<S>,
    [w1, w2]: [V4<S>; 2],
    [n1, n2]: [V4<S>; 2],
    twist: F4<S>,
) -> F4<S> {
    let k = &law.pair;
    let r = law.radius;
    let (f, fd, m1, m2) = pair_interaction_at_lanes(law, g, n1, n2, twist);
    let work = (f - fd).dot(g.v_rel) + m1.dot(w1) + m2.dot(w2);
    // pair_potential_with: rolling, sliding and twisting potentials added in that order.
    let xi = (n1 + n2).times(k.reduced_radius);
    let p = n1.times(r) - n2.times(r);
    let zeta = p - g.nc.scale(p.dot(g.nc));
    let potential = normal
        + 0.5 * k.k_r * xi.dot(xi)
        + 0.5 * k.k_s * zeta.dot(zeta)
        + 0.5 * k.k_t * twist * twist;
    potential + 0.5 * dt * work
}

/// Lane twin of `jkr_potential_at_overlap_with` (x the radius ratio of overlap ratio d).
#[inline(always)]
fn normal_potential_lanes<S: Isa>(law: &ContactLaw, x: F4<S>, d: F4<S>) -> F4<S> {
    let k = &law.pair;
    let zero = jkr_shape_lanes(F4::<S>::splat(X_AT_ZERO_OVERLAP));
    let u = k.f_c * k.delta0 * (jkr_shape_lanes(x) - zero);
    let stretched = u + jkr_force(X_MIN, k.f_c) * (d - D_MIN) * k.delta0;
    F4::<S>::new(std::array::from_fn(|l| {
        if d.0[l] < D_MIN {
            stretched.0[l]
        } else {
            u.0[l]
        }
    }))
}

/// The JKR potential's shape in x, `jkr_potential_at_overlap_with`'s closure. A function, not
/// a closure: a closure is compiled without the caller's `#[target_feature]`, so the AVX
/// instructions in it would become calls.
#[inline(always)]
fn jkr_shape_lanes<S: Isa>(x: F4<S>) -> F4<S> {
    let x2 = x * x;
    4.0 * (1.2 * x2 * x2 * x - 2.0 * x2 * x * x.sqrt() + 0.5 * x2)
}
