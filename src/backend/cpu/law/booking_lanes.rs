//! The step form's corrections of four pair contacts, booked in the lanes as they are made.
//!
//! `Noted::book` (corrections_lanes.rs) books a chunk's corrections after the chunk: each
//! corrected contact's states (before its first correction, after each) noted with its frame,
//! then every state's tangential step energy evaluated four states at a time, then the drops
//! added channel by channel. In the pairs pass (integrate_lanes.rs) everything those energies
//! read is in the lanes already: the frame, the spins, the pointers before and after each
//! correction. So the four contacts' energies are evaluated here, four contacts at a time, and
//! the state after the last correction, the one whose force the pass evaluates next, takes its
//! energy from that force's tangential part instead of evaluating it again. The drops are then
//! added lane by lane in order, the order `Noted::book` adds them, so the tally has its bits.

use super::forces_lanes::{pointers_of, results_of_four};
use super::limits_lanes::{limits_lanes, LimitsLanes};
use super::results::PairResult;
use super::step_energy_lanes::{step_energy_of_tangential, tangential_step_energy_lanes, Frame};
use crate::backend::cpu::lanes::{Isa, F4, V4};
use crate::model::{twisting, ContactLaw};
use crate::state::{Dissipation, PairContact};

/// Four contacts as `integrate_pairs` leaves them in the lanes: owners' and partners'
/// positions after the drift, velocities and spins; the advanced pointers and twist, and the
/// contact normals.
pub(super) struct Advanced<S: Isa> {
    pub x: [V4<S>; 2],
    pub v: [V4<S>; 2],
    pub w: [V4<S>; 2],
    pub n: [V4<S>; 2],
    pub nc: V4<S>,
    pub twist: F4<S>,
}

/// Which corrections one contact had.
#[derive(Clone, Copy, Default)]
struct Had {
    rolled: bool,
    slid: bool,
    twisted: bool,
}

impl Had {
    fn any(self) -> bool {
        self.rolled || self.slid || self.twisted
    }
}

/// The corrections of the `corrected` ones of four contacts (rows `slot[l]` of `rows`, each
/// already advanced to `a`), as `Noted::apply` makes them; then the four contacts' forces
/// into their places (`out`), as `results_of_four`; the corrections' dissipation added to
/// `tally` in `Noted::book`'s order and bits.
#[inline(always)]
pub(super) fn correct_and_book_four<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    (rows, slot): (&mut [PairContact], &[usize; 4]),
    a: &Advanced<S>,
    corrected: [bool; 4],
    out: (&mut [PairResult], &[usize; 4]),
    tally: &mut Dissipation,
) {
    if !corrected.contains(&true) {
        // Nothing moves the pointers: the forces of the lanes as they are.
        results_of_four(law, a.x, a.v, (a.n, a.twist), out);
        return;
    }
    let k = &law.pair;
    let [n1, n2] = a.n;
    // Corrections::found of the twin on the same values: the rolling correction, then the
    // sliding one on the pointers it left.
    let LimitsLanes {
        rolled,
        rolled_n: [rolled_n1, rolled_n2],
        after_roll,
        slid,
        slid_n: [slid_n1, slid_n2],
    } = limits_lanes(law, [n1, n2], a.nc);
    let mut had = [Had::default(); 4];
    for l in 0..4 {
        if !corrected[l] {
            continue;
        }
        let c = &mut rows[slot[l]];
        if rolled.0[l] != 0 {
            c.n1 = rolled_n1.lane(l);
            c.n2 = rolled_n2.lane(l);
            had[l].rolled = true;
        }
        if slid.0[l] != 0 {
            c.n1 = slid_n1.lane(l);
            c.n2 = slid_n2.lane(l);
            had[l].slid = true;
        }
        if let Some(twist) = twisting::twisting_correction(c.twist, k.phi_crit) {
            c.twist = twist;
            had[l].twisted = true;
        }
    }
    let c = [
        &rows[slot[0]],
        &rows[slot[1]],
        &rows[slot[2]],
        &rows[slot[3]],
    ];
    let (n, twist) = pointers_of(c);
    let (t, v_rel) = results_of_four(law, a.x, a.v, (n, twist), out);
    if !had.iter().any(|h| h.any()) {
        return;
    }
    // The state after the last correction is the one just evaluated; the others' energies
    // are evaluated where some lane needs them.
    let last = step_energy_of_tangential(law, dt, &t, v_rel, a.w, twist);
    let frame = Frame::of(a.x[0], a.x[1], a.v[0], a.v[1]);
    let before = tangential_step_energy_lanes(law, dt, &frame, a.w, a.n, a.twist);
    let zero = F4::<S>::splat(0.0);
    let rolled_then_more = had.iter().any(|h| h.rolled && (h.slid || h.twisted));
    let rolled_state = if rolled_then_more {
        tangential_step_energy_lanes(law, dt, &frame, a.w, after_roll, a.twist)
    } else {
        zero
    };
    let slid_then_twisted = had.iter().any(|h| h.slid && h.twisted);
    let slid_state = if slid_then_twisted {
        tangential_step_energy_lanes(law, dt, &frame, a.w, [slid_n1, slid_n2], a.twist)
    } else {
        zero
    };
    for (l, h) in had.into_iter().enumerate() {
        let mut e = before.0[l];
        if h.rolled {
            let after = if h.slid || h.twisted {
                rolled_state.0[l]
            } else {
                last.0[l]
            };
            tally.rolling += e - after;
            e = after;
        }
        if h.slid {
            let after = if h.twisted {
                slid_state.0[l]
            } else {
                last.0[l]
            };
            tally.sliding += e - after;
            e = after;
        }
        if h.twisted {
            tally.twisting += e - last.0[l];
        }
    }
}
