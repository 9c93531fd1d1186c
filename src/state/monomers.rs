//! The monomers: positions, half-step velocities, forces and torques, and which are held.

use glam::DVec3;

/// Per-monomer arrays. `velocity` and `angular_velocity` are half-step values v(n−½) in the
/// leap-frog sense; `force` and `torque` act at the current positions (time n).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Monomers {
    pub position: Vec<DVec3>,
    pub velocity: Vec<DVec3>,
    pub angular_velocity: Vec<DVec3>,
    pub force: Vec<DVec3>,
    pub torque: Vec<DVec3>,
    /// The damping part of `force`, kept to book its work exactly (trapezoid rule).
    pub damping_force: Vec<DVec3>,
    /// 1 for a free monomer, 0 for one held (or driven) in translation.
    pub inverse_mass_scale: Vec<f64>,
    /// 1 for a free monomer, 0 for one whose rotation is held (or driven).
    pub inverse_inertia_scale: Vec<f64>,
}

impl Monomers {
    pub fn new(positions: Vec<DVec3>) -> Self {
        let n = positions.len();
        Monomers {
            position: positions,
            velocity: vec![DVec3::ZERO; n],
            angular_velocity: vec![DVec3::ZERO; n],
            force: vec![DVec3::ZERO; n],
            torque: vec![DVec3::ZERO; n],
            damping_force: vec![DVec3::ZERO; n],
            inverse_mass_scale: vec![1.0; n],
            inverse_inertia_scale: vec![1.0; n],
        }
    }

    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}
