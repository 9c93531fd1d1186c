//! The pair contacts' inelastic corrections: one contact at a time
//! ([`apply_inelastic_limits`]), and those of one chunk of owners four contacts at a time, the
//! same split into its three parts.
//!
//! 1. The rolling and sliding corrections found four contacts at a time (limits_lanes.rs),
//!    then, per contact in order, applied with the twisting one exactly as the scalar code
//!    applies them (they need no energy), and every state whose step energy the scalar code
//!    evaluates noted: the contact before its first correction and after each one.
//! 2. Those step energies' tangential parts (`pair_tangential_step_energy`: a correction
//!    changes nothing else): each corrected contact's frame (distance, normal, relative
//!    velocity), shared between its states as the scalar code shares it, then the energies,
//!    four states at a time.
//! 3. The drops booked channel by channel in the scalar order (owner, contact, rolling before
//!    sliding before twisting), so the tally is the scalar code's to the bit.
//!
//! In a compressed sample most contacts of a flagged owner roll or slide every step, and these
//! energies were most of the contacts pass (DESIGN.md, "The CPU engine on many cores").

use super::limits_lanes::{limits_lanes, LimitsLanes};
use super::step_energy_lanes::{tangential_step_energy_lanes, Frame};
use crate::backend::cpu::chunking::CHUNK;
use crate::backend::cpu::lanes::{in_lanes, ContactLanes, Isa, F4, V4};
use crate::model::{rolling, sliding, twisting, ContactLaw};
use crate::state::interaction::{pair_frame, pair_tangential_step_energy, PairFrame};
use crate::state::{Dissipation, Monomers, PairContact};
use glam::DVec3;

/// Applies the inelastic limits to one contact in the order rolling, sliding, twisting.
///
/// Each correction books its dissipation as the drop of the contact's step energy. A correction
/// moves pointers and twist, never the monomers, so only the tangential part of that energy
/// changes ([`pair_tangential_step_energy`]); its states share the contact's [`PairFrame`],
/// made at the first correction only (most contacts of a loose sample need none, and then
/// nothing extra is evaluated), and one correction's "after" is the next one's "before".
pub fn apply_inelastic_limits(
    law: &ContactLaw,
    monomers: &Monomers,
    dt: f64,
    i: usize,
    c: &mut PairContact,
    tally: &mut Dissipation,
) {
    let k = &law.pair;
    let r = law.radius;
    let j = c.partner as usize;
    let (p, v, w) = (
        &monomers.position,
        &monomers.velocity,
        &monomers.angular_velocity,
    );
    let nc = (p[i] - p[j]).normalize();
    let mut frame: Option<PairFrame> = None;
    let mut energy = |c: &PairContact| {
        let f = *frame.get_or_insert_with(|| pair_frame(p[i], p[j], v[i], v[j]));
        pair_tangential_step_energy(law, &f, w[i], w[j], dt, c)
    };
    // The step energy of the contact as it stands.
    let mut current = None;
    if let Some((n1, n2)) = rolling::rolling_correction(c.n1, c.n2, k.reduced_radius, k.xi_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.n1 = n1;
        c.n2 = n2;
        let after = energy(c);
        tally.rolling += before - after;
        current = Some(after);
    }
    if let Some((n1, n2)) = sliding::sliding_correction(c.n1, c.n2, nc, r, r, k.zeta_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.n1 = n1;
        c.n2 = n2;
        let after = energy(c);
        tally.sliding += before - after;
        current = Some(after);
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
        let before = current.unwrap_or_else(|| energy(c));
        c.twist = twist;
        tally.twisting += before - energy(c);
    }
}

/// One state whose step energy the booking needs: contact `contact` of the chunk's corrected
/// contacts as it stood then (its pointers and twist: a table slot, 64-byte aligned, would
/// double the note).
#[derive(Clone, Copy)]
struct EnergyOf {
    contact: usize,
    n1: DVec3,
    n2: DVec3,
    twist: f64,
}

impl EnergyOf {
    fn of(contact: usize, c: &PairContact) -> Self {
        EnergyOf {
            contact,
            n1: c.n1,
            n2: c.n2,
            twist: c.twist,
        }
    }

    /// The state as a contact (its partner is not read by the energy).
    fn state(&self) -> PairContact {
        PairContact {
            partner: 0,
            n1: self.n1,
            n2: self.n2,
            twist: self.twist,
        }
    }
}

/// A corrected contact: owner and partner.
#[derive(Clone, Copy)]
struct Corrected {
    i: usize,
    j: usize,
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
/// their dissipation added to `tally`; with no tally (its channels not booked), the
/// corrections alone, the same contacts to the bit without the step energies.
pub fn chunk_corrections<'a>(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    rows: impl Iterator<Item = (usize, &'a mut [PairContact])>,
    mut tally: Option<&mut Dissipation>,
) {
    if let (ContactLanes::Scalar, Some(tally)) = (lanes, tally.as_deref_mut()) {
        for (i, contacts) in rows {
            for c in contacts {
                apply_inelastic_limits(law, m, dt, i, c, tally);
            }
        }
        return;
    }
    let mut pending: Vec<(usize, &mut PairContact)> = Vec::with_capacity(2 * CHUNK);
    for (i, row) in rows {
        pending.extend(row.iter_mut().map(|c| (i, c)));
    }
    // Without a tally nothing is noted: the corrections alone, found as the booking path
    // finds them.
    let mut noted = Noted::with_room_for(pending.len(), tally.is_some());
    let (p, v) = (&m.position, &m.velocity);
    in_lanes!(
        lanes,
        correct_in_lanes(law, m, &mut pending, &mut noted)
            as (
                law: &ContactLaw,
                m: &Monomers,
                pending: &mut [(usize, &mut PairContact)],
                noted: &mut Noted,
            ),
        scalar => {
            for (i, c) in pending {
                let j = c.partner as usize;
                let found = Found::at(law, p[i], p[j], c);
                noted.apply(law, i, c, found, || pair_frame(p[i], p[j], v[i], v[j]));
            }
        },
    );
    if let Some(tally) = tally {
        noted.book(lanes, law, dt, m, tally);
    }
}

impl Noted {
    /// Books what the noted corrections dissipated into `tally`: the step energies of every
    /// noted state, `lanes` wide, then the drops channel by channel in the order noted (owner,
    /// contact, rolling before sliding before twisting), the scalar code's order and bits.
    pub fn book(
        self,
        lanes: ContactLanes,
        law: &ContactLaw,
        dt: f64,
        m: &Monomers,
        tally: &mut Dissipation,
    ) {
        let Noted {
            states,
            contacts,
            frames,
            bookings,
            ..
        } = self;
        let energies = step_energies(lanes, law, dt, m, &contacts, &frames, &states);
        book_drops(&bookings, &energies, tally);
    }
}

/// The drops of the step energies `energies` booked channel by channel, contact by contact.
fn book_drops(bookings: &[Booking], energies: &[f64], tally: &mut Dissipation) {
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

/// What the corrections noted for their step energies: every state to evaluate, in order,
/// the corrected contacts with their frames, and which corrections each had; nothing where
/// not `noting`.
pub struct Noted {
    states: Vec<EnergyOf>,
    contacts: Vec<Corrected>,
    frames: Vec<PairFrame>,
    bookings: Vec<Booking>,
    noting: bool,
}

/// The rolling and sliding corrections one contact needs (sliding on the pointers the rolling
/// correction left), found four at a time or one at a time.
pub(super) struct Found {
    pub(super) rolled: Option<(DVec3, DVec3)>,
    pub(super) slid: Option<(DVec3, DVec3)>,
}

impl Found {
    /// The scalar code's, for the contact's monomers at `x1` and `x2`: `rolling_correction`,
    /// then `sliding_correction`.
    pub(super) fn at(law: &ContactLaw, x1: DVec3, x2: DVec3, c: &PairContact) -> Found {
        let k = &law.pair;
        let r = law.radius;
        let nc = (x1 - x2).normalize();
        let rolled = rolling::rolling_correction(c.n1, c.n2, k.reduced_radius, k.xi_crit);
        let (a, b) = rolled.unwrap_or((c.n1, c.n2));
        let slid = sliding::sliding_correction(a, b, nc, r, r, k.zeta_crit);
        Found { rolled, slid }
    }
}

impl Noted {
    /// Room for `contacts` corrected contacts: the states of all four of their corrections'
    /// energies fit without growing (the growth's copies were a fifth of the notes' cost).
    pub fn with_room_for(contacts: usize, noting: bool) -> Noted {
        let room = if noting { contacts } else { 0 };
        Noted {
            states: Vec::with_capacity(4 * room),
            contacts: Vec::with_capacity(room),
            frames: Vec::with_capacity(room),
            bookings: Vec::with_capacity(room),
            noting,
        }
    }

    /// `apply_inelastic_limits` without the energies: the corrections `found` (and the
    /// twisting one) applied to contact `c` of owner `i`, the states to evaluate noted with
    /// the contact's `frame` (made only for a contact corrected).
    // Called per corrected contact from the lanes' loop: as a call it cost 3 % of a
    // compressed sample's step instructions and about 10 % of its time.
    #[inline(always)]
    pub(super) fn apply(
        &mut self,
        law: &ContactLaw,
        i: usize,
        c: &mut PairContact,
        found: Found,
        frame: impl FnOnce() -> PairFrame,
    ) {
        if !self.noting {
            return apply_found(law, c, found);
        }
        let contact = self.contacts.len();
        let first = self.states.len();
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
                states.push(EnergyOf::of(contact, &before));
            }
            states.push(EnergyOf::of(contact, c));
        };
        if let Some((n1, n2)) = found.rolled {
            c.n1 = n1;
            c.n2 = n2;
            corrected(c, &mut self.states);
            booking.rolled = true;
        }
        if let Some((n1, n2)) = found.slid {
            c.n1 = n1;
            c.n2 = n2;
            corrected(c, &mut self.states);
            booking.slid = true;
        }
        if let Some(twist) = twisting::twisting_correction(c.twist, law.pair.phi_crit) {
            c.twist = twist;
            corrected(c, &mut self.states);
            booking.twisted = true;
        }
        if booking.rolled || booking.slid || booking.twisted {
            let j = c.partner as usize;
            self.contacts.push(Corrected { i, j });
            self.frames.push(frame());
            self.bookings.push(booking);
        }
    }
}

/// The corrections `found` and the twisting one applied to `c`, in the scalar order.
fn apply_found(law: &ContactLaw, c: &mut PairContact, found: Found) {
    if let Some((n1, n2)) = found.rolled {
        c.n1 = n1;
        c.n2 = n2;
    }
    if let Some((n1, n2)) = found.slid {
        c.n1 = n1;
        c.n2 = n2;
    }
    if let Some(twist) = twisting::twisting_correction(c.twist, law.pair.phi_crit) {
        c.twist = twist;
    }
}

/// The corrections of the `pending` contacts (owner, contact), in order: their rolling and
/// sliding corrections found four at a time (a last batch of fewer one at a time), then
/// applied contact by contact.
#[inline(always)]
fn correct_in_lanes<S: Isa>(
    law: &ContactLaw,
    m: &Monomers,
    pending: &mut [(usize, &mut PairContact)],
    noted: &mut Noted,
) {
    let (p, v) = (&m.position, &m.velocity);
    let mut batches = pending.chunks_exact_mut(4);
    for four in &mut batches {
        let x1 = V4::<S>::gather(|l| p[four[l].0]);
        let x2 = V4::<S>::gather(|l| p[four[l].1.partner as usize]);
        let nc = (x1 - x2).normalize();
        let n1 = V4::<S>::gather(|l| four[l].1.n1);
        let n2 = V4::<S>::gather(|l| four[l].1.n2);
        let LimitsLanes {
            rolled,
            rolled_n: [rolled_n1, rolled_n2],
            slid,
            slid_n: [slid_n1, slid_n2],
            ..
        } = limits_lanes(law, [n1, n2], nc);
        for (l, (i, c)) in four.iter_mut().enumerate() {
            let found = Found {
                rolled: (rolled.0[l] != 0).then(|| (rolled_n1.lane(l), rolled_n2.lane(l))),
                slid: (slid.0[l] != 0).then(|| (slid_n1.lane(l), slid_n2.lane(l))),
            };
            let (i, j) = (*i, c.partner as usize);
            noted.apply(law, i, c, found, || pair_frame(p[i], p[j], v[i], v[j]));
        }
    }
    for (i, c) in batches.into_remainder() {
        let (i, j) = (*i, c.partner as usize);
        let found = Found::at(law, p[i], p[j], c);
        noted.apply(law, i, c, found, || pair_frame(p[i], p[j], v[i], v[j]));
    }
}

/// The tangential step energy of every noted state, in order, `lanes` wide, from its
/// contact's frame; a last batch of fewer than four goes through the scalar code.
fn step_energies(
    lanes: ContactLanes,
    law: &ContactLaw,
    dt: f64,
    m: &Monomers,
    contacts: &[Corrected],
    frames: &[PairFrame],
    states: &[EnergyOf],
) -> Vec<f64> {
    let mut energies = vec![0.0; states.len()];
    let batches = states.len() / 4;
    let at = Energies {
        law,
        dt,
        m,
        contacts,
        frames,
    };
    // The scalar choice too evaluates these four at a time, in the portable lanes.
    in_lanes!(
        lanes,
        energies_in_lanes(&at, &states[..4 * batches], &mut energies)
            as (at: &Energies, states: &[EnergyOf], energies: &mut [f64]),
    );
    let w = &m.angular_velocity;
    for (k, s) in states.iter().enumerate().skip(4 * batches) {
        let Corrected { i, j } = contacts[s.contact];
        let frame = &frames[s.contact];
        energies[k] = pair_tangential_step_energy(law, frame, w[i], w[j], dt, &s.state());
    }
    energies
}

/// What the step energies of the noted states read.
struct Energies<'a> {
    law: &'a ContactLaw,
    dt: f64,
    m: &'a Monomers,
    contacts: &'a [Corrected],
    frames: &'a [PairFrame],
}

#[inline(always)]
fn energies_in_lanes<S: Isa>(at: &Energies, states: &[EnergyOf], energies: &mut [f64]) {
    let w = &at.m.angular_velocity;
    for (four, out) in states.chunks_exact(4).zip(energies.chunks_exact_mut(4)) {
        let contact = |l: usize| at.contacts[four[l].contact];
        let frame = |l: usize| &at.frames[four[l].contact];
        let e = tangential_step_energy_lanes(
            at.law,
            at.dt,
            &Frame {
                distance: F4::<S>::new(std::array::from_fn(|l| frame(l).distance)),
                nc: V4::<S>::gather(|l| frame(l).nc),
                v_rel: V4::<S>::gather(|l| frame(l).v_rel),
            },
            [
                V4::<S>::gather(|l| w[contact(l).i]),
                V4::<S>::gather(|l| w[contact(l).j]),
            ],
            [
                V4::<S>::gather(|l| four[l].n1),
                V4::<S>::gather(|l| four[l].n2),
            ],
            F4::<S>::new(std::array::from_fn(|l| four[l].twist)),
        );
        out.copy_from_slice(&e.0);
    }
}
