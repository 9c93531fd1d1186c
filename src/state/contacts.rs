//! The contact history: one record per pair or wall contact, in fixed per-monomer slots (the
//! contact table), as both backends store it.

use glam::DVec3;

/// Contact slots per monomer for partners of higher index (equal spheres touch at most 12).
pub const DEFAULT_PAIR_SLOTS: usize = 12;
/// The most pair slots a configuration may give a monomer (the contacts pass keeps a row's
/// partners on the stack).
pub const MAX_PAIR_SLOTS: usize = 64;
/// Wall contact slots per monomer (a box corner touches 3 walls).
pub const DEFAULT_WALL_SLOTS: usize = 3;

/// History of one monomer–monomer contact, stored with its lower-index monomer (the owner).
/// Aligned to 64 bytes (its size): each slot one cache line, not two halves of neighbours'
/// (docs/guide/src/benchmarks.md, "CPU engine: one cache line per contact slot").
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(align(64))]
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
#[repr(align(64))]
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
    /// A table with no contacts. Slots per monomer must be at least 1 (the configuration checks
    /// this; the passes split the table into rows of that length).
    pub fn new(n: usize, pair_slots: usize, wall_slots: usize) -> Self {
        assert!(
            pair_slots >= 1 && wall_slots >= 1,
            "contact slots per monomer must be at least 1 (pair {pair_slots}, wall {wall_slots})"
        );
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
