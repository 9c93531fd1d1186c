//! The pair contacts' rolling and sliding limits four contacts at a time: the lane twins of
//! `rolling_correction` (model/rolling.rs) and `sliding_correction` (model/sliding.rs), found
//! in the scalar code's order by [`limits_lanes`], the one function the lane passes call.
//!
//! Each lane does its contact's scalar operations in the scalar order (lanes/four.rs), and the
//! sliding correction's repeated step is masked as the JKR inversion's Newton loop is: a lane
//! stops after the iteration at which the scalar loop breaks, its pointers then held. Lanes
//! within a limit compute the corrected pointers too, and the mask discards them, so every
//! lane ends with the scalar code's bits.

use crate::backend::cpu::lanes::{Isa, F4, M4, V4};
use crate::model::ContactLaw;

/// The rolling and sliding corrections of four contacts: which lanes roll and their pointers
/// (meaningless where not set), the pointers after rolling (each lane's own where it does
/// not), which lanes slide from there and their pointers.
pub(crate) struct LimitsLanes<S: Isa> {
    pub rolled: M4<S>,
    pub rolled_n: [V4<S>; 2],
    pub after_roll: [V4<S>; 2],
    pub slid: M4<S>,
    pub slid_n: [V4<S>; 2],
}

/// The corrections four contacts with pointers `n1`, `n2` and normals `nc` need, as the scalar
/// code finds them (`Found::at`, corrections_lanes.rs): `rolling_correction`, then
/// `sliding_correction` on the pointers it left.
#[inline(always)]
pub(crate) fn limits_lanes<S: Isa>(
    law: &ContactLaw,
    [n1, n2]: [V4<S>; 2],
    nc: V4<S>,
) -> LimitsLanes<S> {
    let k = &law.pair;
    let (rolled, rolled_n1, rolled_n2) =
        rolling_correction_lanes(n1, n2, k.reduced_radius, k.xi_crit);
    let after_roll = [
        V4::select(rolled, rolled_n1, n1),
        V4::select(rolled, rolled_n2, n2),
    ];
    let (slid, slid_n1, slid_n2) =
        sliding_correction_lanes(after_roll[0], after_roll[1], nc, law.radius, k.zeta_crit);
    LimitsLanes {
        rolled,
        rolled_n: [rolled_n1, rolled_n2],
        after_roll,
        slid,
        slid_n: [slid_n1, slid_n2],
    }
}

/// Lane twin of `rolling_correction`: which lanes roll past ξ_crit (`|n₁ + n₂| R_red > ξ_crit`,
/// a NaN counting as past), with their corrected pointers (meaningless where not set).
#[inline(always)]
fn rolling_correction_lanes<S: Isa>(
    n1: V4<S>,
    n2: V4<S>,
    reduced_radius: f64,
    xi_crit: f64,
) -> (M4<S>, V4<S>, V4<S>) {
    let s = n1 + n2;
    let xi = s.length() * reduced_radius;
    let beyond = M4::ALL.and_not(xi.le(F4::splat(xi_crit)));
    let s_new = s.scale(xi_crit / xi);
    let t = n1 - n2;
    let t_perp = t - s_new.scale(t.dot(s_new) / s_new.dot(s_new));
    let t_new = t_perp.scale((4.0 - s_new.dot(s_new)).sqrt() / t_perp.length());
    (
        beyond,
        (s_new + t_new).times(0.5),
        (s_new - t_new).times(0.5),
    )
}

/// Lane twin of `sliding_displacement` for two monomers of radius `r`.
#[inline(always)]
fn sliding_displacement_lanes<S: Isa>(n1: V4<S>, n2: V4<S>, nc: V4<S>, r: f64) -> V4<S> {
    let p = n1.times(r) - n2.times(r);
    p - nc.scale(p.dot(nc))
}

/// Lane twin of `sliding_correction` for two monomers of radius `r`: which lanes slide past
/// ζ_crit, with their corrected pointers (the given ones where not set).
#[inline(always)]
fn sliding_correction_lanes<S: Isa>(
    n1: V4<S>,
    n2: V4<S>,
    nc: V4<S>,
    r: f64,
    zeta_crit: f64,
) -> (M4<S>, V4<S>, V4<S>) {
    let mut zeta = sliding_displacement_lanes(n1, n2, nc, r);
    let beyond = M4::ALL.and_not(zeta.length().le(F4::splat(zeta_crit)));
    let (mut a, mut b) = (n1, n2);
    let mut active = beyond;
    let close_enough = F4::splat(zeta_crit * (1.0 + 1e-13));
    let twice_r = F4::splat(2.0 * r);
    for _ in 0..6 {
        let len = zeta.length();
        active = active.and_not(len.le(close_enough));
        if !active.any() {
            break;
        }
        let dz = zeta.scale(1.0 - zeta_crit / len);
        let next_a = (a - dz.divide(twice_r)).normalize();
        let next_b = (b + dz.divide(twice_r)).normalize();
        let next_zeta = sliding_displacement_lanes(next_a, next_b, nc, r);
        a = V4::select(active, next_a, a);
        b = V4::select(active, next_b, b);
        zeta = V4::select(active, next_zeta, zeta);
    }
    (beyond, a, b)
}
