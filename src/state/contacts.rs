//! Engine state shared by the CPU passes: monomers, contact history, walls, energy tally.

use crate::material::ContactConstants;
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

/// History of one monomer–monomer contact, stored with its lower-index monomer (the owner).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairContact {
    pub partner: u32,
    /// Pointer of the owner.
    pub n1: DVec3,
    /// Pointer of the partner.
    pub n2: DVec3,
    /// Twist integral ∫(ω₁ − ω₂)·n_c dt [rad].
    pub twist: f64,
}

/// History of one monomer–wall contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallContact {
    pub wall: u32,
    /// Pointer of the monomer.
    pub n1: DVec3,
    /// Where the contact formed on the wall, carried along by inelastic sliding.
    pub anchor: DVec3,
    pub twist: f64,
}

/// Fixed slots per monomer (as on the GPU): owners hold up to `pair_slots` contacts with
/// higher-index partners and up to `wall_slots` wall contacts. A full slot is an error.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactTable {
    pub pair_slots: usize,
    pub wall_slots: usize,
    pub pair: Vec<PairContact>,
    pub pair_count: Vec<u32>,
    pub wall: Vec<WallContact>,
    pub wall_count: Vec<u32>,
}

impl ContactTable {
    pub fn new(n: usize, pair_slots: usize, wall_slots: usize) -> Self {
        let empty_pair = PairContact {
            partner: u32::MAX,
            n1: DVec3::ZERO,
            n2: DVec3::ZERO,
            twist: 0.0,
        };
        let empty_wall = WallContact {
            wall: u32::MAX,
            n1: DVec3::ZERO,
            anchor: DVec3::ZERO,
            twist: 0.0,
        };
        ContactTable {
            pair_slots,
            wall_slots,
            pair: vec![empty_pair; n * pair_slots],
            pair_count: vec![0; n],
            wall: vec![empty_wall; n * wall_slots],
            wall_count: vec![0; n],
        }
    }

    pub fn pairs_of(&self, i: usize) -> &[PairContact] {
        let start = i * self.pair_slots;
        &self.pair[start..start + self.pair_count[i] as usize]
    }

    pub fn walls_of(&self, i: usize) -> &[WallContact] {
        let start = i * self.wall_slots;
        &self.wall[start..start + self.wall_count[i] as usize]
    }

    pub fn has_pair(&self, i: usize, j: u32) -> bool {
        self.pairs_of(i).iter().any(|c| c.partner == j)
    }

    pub fn has_wall(&self, i: usize, w: u32) -> bool {
        self.walls_of(i).iter().any(|c| c.wall == w)
    }

    pub fn pair_contact_count(&self) -> usize {
        self.pair_count.iter().map(|&c| c as usize).sum()
    }

    pub fn wall_contact_count(&self) -> usize {
        self.wall_count.iter().map(|&c| c as usize).sum()
    }

    /// Contacts per monomer, counting each pair contact for both monomers.
    pub fn coordination(&self) -> Vec<u32> {
        let mut count: Vec<u32> = self.pair_count.clone();
        for i in 0..count.len() {
            for c in self.pairs_of(i) {
                count[c.partner as usize] += 1;
            }
        }
        count
    }
}

/// A planar wall moving at constant velocity. `normal` points into the domain.
#[derive(Clone, Debug, PartialEq)]
pub struct Wall {
    pub name: String,
    pub point: DVec3,
    pub normal: DVec3,
    pub velocity: DVec3,
    /// Contact constants with this wall's strength factors applied.
    pub constants: ContactConstants,
}

/// Energy removed from the monomers' mechanical energy, per channel [erg].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dissipation {
    /// Potential left in monomer–monomer contacts when they break.
    pub breaking: f64,
    /// Minus the potential a contact has when it is found (formed slightly past δ = 0).
    pub forming: f64,
    /// Normal damping, monomer–monomer and monomer–wall.
    pub damping: f64,
    pub rolling: f64,
    pub sliding: f64,
    pub twisting: f64,
    /// Inelastic rolling, sliding, twisting, forming and breaking of wall contacts.
    pub walls: f64,
}

impl Dissipation {
    /// The channels in a fixed order (checkpoints, the GPU tally): breaking, forming, damping,
    /// rolling, sliding, twisting, walls.
    pub fn channels(&self) -> [f64; 7] {
        [
            self.breaking,
            self.forming,
            self.damping,
            self.rolling,
            self.sliding,
            self.twisting,
            self.walls,
        ]
    }

    /// The inverse of [`Dissipation::channels`].
    pub fn from_channels(c: [f64; 7]) -> Self {
        let [breaking, forming, damping, rolling, sliding, twisting, walls] = c;
        Dissipation {
            breaking,
            forming,
            damping,
            rolling,
            sliding,
            twisting,
            walls,
        }
    }

    pub fn total(&self) -> f64 {
        self.breaking
            + self.forming
            + self.damping
            + self.rolling
            + self.sliding
            + self.twisting
            + self.walls
    }
}
