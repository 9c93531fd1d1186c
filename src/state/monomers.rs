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
    /// The monomer's number in the sample it came from: the engines may store monomers in
    /// another order (space-filling order, [`super::order`]), outputs name them by this id.
    pub id: Vec<u32>,
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
            id: (0..n as u32).collect(),
        }
    }

    /// The monomers in another order: entry k of the result is entry `order[k]` of `self`.
    pub fn permuted(&self, order: &[u32]) -> Monomers {
        fn take<T: Copy>(v: &[T], order: &[u32]) -> Vec<T> {
            order.iter().map(|&i| v[i as usize]).collect()
        }
        Monomers {
            position: take(&self.position, order),
            velocity: take(&self.velocity, order),
            angular_velocity: take(&self.angular_velocity, order),
            force: take(&self.force, order),
            torque: take(&self.torque, order),
            damping_force: take(&self.damping_force, order),
            inverse_mass_scale: take(&self.inverse_mass_scale, order),
            inverse_inertia_scale: take(&self.inverse_inertia_scale, order),
            id: take(&self.id, order),
        }
    }

    /// Where each sample id is stored: `slot[id]` is the index holding monomer `id`, if the
    /// ids are a permutation of 0..n (as every engine keeps them).
    pub fn index_of_ids(&self) -> Option<Vec<usize>> {
        let n = self.len();
        let mut slot = vec![usize::MAX; n];
        for (i, &id) in self.id.iter().enumerate() {
            let s = slot.get_mut(id as usize)?;
            if *s != usize::MAX {
                return None;
            }
            *s = i;
        }
        Some(slot)
    }

    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}
