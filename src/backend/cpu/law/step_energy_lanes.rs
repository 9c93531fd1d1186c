//! The tangential step energy of four pair contacts at a time: their frame (`pair_frame`'s
//! lane twin) and `pair_tangential_step_energy`'s, shared by the corrections, their booking
//! and the pairs pass.

use super::forces_lanes::{pair_tangential_lanes, TangentialLanes};
use crate::backend::cpu::lanes::{Isa, F4, V4};
use crate::model::ContactLaw;
use crate::state::interaction::PairFrame;

/// `PairFrame` of four contacts.
pub(super) struct Frame<S: Isa> {
    pub distance: F4<S>,
    pub nc: V4<S>,
    pub v_rel: V4<S>,
}

impl<S: Isa> Frame<S> {
    /// `pair_frame` of four contacts: the lanes' operations in its order, the same bits.
    #[inline(always)]
    pub fn of(x1: V4<S>, x2: V4<S>, v1: V4<S>, v2: V4<S>) -> Self {
        let d = x1 - x2;
        let distance = d.length();
        Frame {
            distance,
            nc: d.divide(distance),
            v_rel: v1 - v2,
        }
    }

    /// Lane `l` as a `PairFrame`.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> PairFrame {
        PairFrame {
            distance: self.distance.0[l],
            nc: self.nc.lane(l),
            v_rel: self.v_rel.lane(l),
        }
    }
}

/// Lane twin of `pair_tangential_step_energy`: the contacts' frames, the spins of owner and
/// partner, the pointers and the twist.
#[inline(always)]
pub(super) fn tangential_step_energy_lanes<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    f: &Frame<S>,
    spins: [V4<S>; 2],
    [n1, n2]: [V4<S>; 2],
    twist: F4<S>,
) -> F4<S> {
    let t = pair_tangential_lanes(law, f.nc, f.distance, n1, n2, twist);
    step_energy_of_tangential(law, dt, &t, f.v_rel, spins, twist)
}

/// The step energy of four contacts whose tangential part `t` (`pair_tangential_lanes`) is
/// known: the potentials of its displacements and of `twist`, plus half a step's work of its
/// force and torques at the relative velocity `v_rel` and the spins `w1`, `w2`.
#[inline(always)]
pub(super) fn step_energy_of_tangential<S: Isa>(
    law: &ContactLaw,
    dt: f64,
    t: &TangentialLanes<S>,
    v_rel: V4<S>,
    [w1, w2]: [V4<S>; 2],
    twist: F4<S>,
) -> F4<S> {
    let k = &law.pair;
    let work = t.slide.dot(v_rel) + t.torque1.dot(w1) + t.torque2.dot(w2);
    // rolling, sliding and twisting potentials added in that order.
    let potential = 0.5 * k.k_r * t.xi.dot(t.xi)
        + 0.5 * k.k_s * t.zeta.dot(t.zeta)
        + 0.5 * k.k_t * twist * twist;
    potential + 0.5 * dt * work
}
