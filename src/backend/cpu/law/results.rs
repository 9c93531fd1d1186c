//! What the per-contact code hands the passes: each contact's result ([`PairResult`],
//! [`WallResult`]), where a chunk's results go ([`ResultPlaces`]) and the chunk of owners a
//! per-contact pass hands over ([`OwnerChunk`]).

use crate::backend::cpu::prefetch::{
    prefetch_one, prefetch_partners_ahead, prefetch_row_ahead, Prefetching,
};
use crate::state::{Monomers, PairContact};
use glam::DVec3;

/// What one pair contact exerts: the force on its owner, the damping part of it, and the
/// torques on owner and partner.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairResult {
    pub force: DVec3,
    pub damping: DVec3,
    pub torque_owner: DVec3,
    pub torque_partner: DVec3,
}

/// What one wall contact exerts on its monomer: the force, its damping part, the torque.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallResult {
    pub force: DVec3,
    pub damping: DVec3,
    pub torque: DVec3,
}

/// One chunk of owners as a per-contact pass hands it over: their contact slots (`slots` per
/// owner; `R` is `&[PairContact]` for the force pass, `&mut` for `integrate_pairs`), contacts
/// per owner, the first owner's index, and whether to prefetch rows and partners ahead
/// (`prefetch::worthwhile`).
#[derive(Clone, Copy)]
pub struct OwnerChunk<'a, R> {
    pub rows: R,
    pub slots: usize,
    pub counts: &'a [u32],
    pub first: usize,
    pub prefetching: Prefetching,
}

impl<R: std::ops::Deref<Target = [PairContact]>> OwnerChunk<'_, R> {
    /// Prefetches what owner `k` of the chunk will need a few owners from now: its partners'
    /// positions and velocities, and their spins where `spins`.
    #[inline(always)]
    pub(super) fn prefetch_ahead(&self, m: &Monomers, k: usize, spins: bool) {
        if self.prefetching != Prefetching::Off {
            prefetch_row_ahead(&self.rows, self.slots, self.counts, k);
        }
        if self.prefetching == Prefetching::RowsAndPartners {
            prefetch_partners_ahead(&self.rows, self.slots, self.counts, k, |j| {
                prefetch_one(&m.position[j]);
                prefetch_one(&m.velocity[j]);
                if spins {
                    prefetch_one(&m.angular_velocity[j]);
                }
            });
        }
    }

    /// The slots of owner `k`'s contacts.
    #[inline(always)]
    pub(super) fn contacts_of(&self, k: usize) -> std::ops::Range<usize> {
        k * self.slots..k * self.slots + self.counts[k] as usize
    }
}

/// Where a chunk's per-contact results go: its stretch of them, and owner `k`'s first place
/// in it, `starts[k] - base` (the partner index's places); without `starts`, the owners'
/// results one after another.
pub struct ResultPlaces<'a> {
    pub results: &'a mut [PairResult],
    pub starts: Option<&'a [u32]>,
    pub base: u32,
}

impl ResultPlaces<'_> {
    /// The first place of owner `k` of the chunk, `next` being the place after the owners
    /// before it where they follow one another.
    #[inline(always)]
    pub fn owner(&self, k: usize, next: usize) -> usize {
        match self.starts {
            Some(starts) => (starts[k] - self.base) as usize,
            None => next,
        }
    }
}
