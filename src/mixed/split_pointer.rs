//! Contact pointers in f32 pairs: each component a double-f32 (hi + lo), turned by an increment
//! computed in f32.
//!
//! A plain f32 pointer turned by the same small angle every step rounds by the same fraction
//! of its ulp every step: at 10⁻⁶ rad per step it is 1.3 % behind after 10⁵ steps, a rolling
//! displacement error of 0.2 ξ_crit (`tests/precision_budget.rs`). Here the turn's increment
//! Δ = n(cos θ − 1) + (w × n) sin θ/θ + w (w·n)(1 − cos θ)/θ², of size θ, is computed in f32
//! from the high parts (relative error 10⁻⁷ of Δ, not of n) and added to the pair exactly
//! (TwoSum). The length is not renormalised: the increment keeps it to 10⁻⁷ θ per step.

use super::double_f32::DoubleF32;
use glam::{DVec3, Vec3};

/// A unit vector as hi + lo per component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitUnit {
    pub hi: Vec3,
    pub lo: Vec3,
}

impl SplitUnit {
    pub fn from_f64(n: DVec3) -> Self {
        let hi = n.as_vec3();
        SplitUnit {
            hi,
            lo: (n - hi.as_dvec3()).as_vec3(),
        }
    }

    pub fn to_f64(self) -> DVec3 {
        self.hi.as_dvec3() + self.lo.as_dvec3()
    }
}

/// The pointer turned by the rotation vector `w` (angle |w| [rad] about w/|w|); the twin of
/// `model::pointer::rotate_pointer` in increment form, with its series for sin θ/θ and
/// (1 − cos θ)/θ² cut where f32 ends (θ ≤ 0.3: the next term is below 10⁻⁸).
pub fn rotate_split_pointer(n: SplitUnit, w: Vec3) -> SplitUnit {
    let t2 = w.length_squared();
    if t2 == 0.0 {
        return n;
    }
    let sinc = 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * 0.05 * (1.0 - t2 * (1.0 / 42.0)));
    let cosc = 0.5 * (1.0 - t2 * (1.0 / 12.0) * (1.0 - t2 * (1.0 / 30.0)));
    let h = n.hi;
    let delta = w.cross(h) * sinc + (w * w.dot(h) - h * t2) * cosc;
    let mut out = n;
    for axis in 0..3 {
        let sum = DoubleF32 {
            hi: n.hi[axis],
            lo: n.lo[axis],
        }
        .add_f32(delta[axis]);
        out.hi[axis] = sum.hi;
        out.lo[axis] = sum.lo;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_turn_in_small_steps_lands_on_the_axis() {
        // z turned about x by π/2 in 10⁵ steps ends at −y.
        let steps = 100_000;
        let w = Vec3::new(
            (std::f64::consts::FRAC_PI_2 / steps as f64) as f32,
            0.0,
            0.0,
        );
        let mut n = SplitUnit::from_f64(DVec3::Z);
        for _ in 0..steps {
            n = rotate_split_pointer(n, w);
        }
        let end = n.to_f64();
        // The angle per step is an f32 (relative rounding 3e-8): the end is that far off.
        assert!((end - DVec3::NEG_Y).length() < 1e-7, "{end}");
        assert!((end.length() - 1.0).abs() < 1e-9, "{}", end.length());
    }
}
