//! Software prefetch of the rows a pass will reach a few owners from now.
//!
//! The passes walk owners in order, but an owner's contact row sits `pair_slots` records after
//! the previous one and many rows are empty, so the hardware prefetchers do not follow; with
//! 10⁵ monomers the table is larger than the last-level cache and every row was a memory
//! round trip that the long per-contact arithmetic kept from overlapping with the next
//! (docs/guide/src/benchmarks.md, "CPU engine: prefetching contact rows"). A hint changes no
//! value, only when a line arrives, so results are bit-identical with or without it.
//!
//! The hints themselves, below the contact law; when the passes give them is theirs to
//! decide (passes/prefetching.rs).

/// Owners ahead of the current one whose partners' monomer data are requested: half of
/// [`AHEAD`], so their rows (requested `AHEAD / 2` owners ago) have usually arrived.
pub const PARTNERS_AHEAD: usize = AHEAD / 2;

/// Owners ahead of the current one whose rows are requested: far enough for a memory round
/// trip (about 100 ns) to finish while the owners between are processed (tens of ns each),
/// near enough for the lines to stay in the first-level cache.
pub const AHEAD: usize = 8;

use crate::state::PairContact;

const LINE: usize = 64;

/// What a per-contact pass (`integrate_pairs`, `forces`) prefetches a few owners ahead
/// (passes/prefetching.rs decides).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prefetching {
    Off,
    /// The rows only: a hint that never waits.
    Rows,
    /// The rows, and the partners' monomer data, whose indices are read from a row requested
    /// [`PARTNERS_AHEAD`] owners before: a load that waits where that row has not arrived.
    RowsAndPartners,
}

/// Asks for the cache lines of `items` (no-op on architectures without a stable hint).
#[inline(always)]
pub fn prefetch<T>(items: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let bytes = std::mem::size_of_val(items);
        if bytes == 0 {
            return;
        }
        let start = items.as_ptr() as usize;
        let mut line = start & !(LINE - 1);
        while line < start + bytes {
            // SAFETY: a prefetch hint neither reads nor writes program-visible memory and never
            // faults, even for an unmapped address; SSE, which provides it, is part of the
            // x86_64 baseline.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(line as *const i8) };
            line += LINE;
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = items;
}

/// Prefetches the used part of the row of owner `k + AHEAD` of a chunk (`rows` holds the
/// chunk's rows of `slots` records, `counts` its counts), if that owner is in the chunk.
#[inline(always)]
pub fn prefetch_row_ahead<T>(rows: &[T], slots: usize, counts: &[u32], k: usize) {
    let ahead = k + AHEAD;
    if let Some(&count) = counts.get(ahead) {
        let start = ahead * slots;
        prefetch(&rows[start..start + count as usize]);
    }
}

/// Calls `request(partner)` for each contact of owner `k + PARTNERS_AHEAD` of a chunk, to
/// prefetch the partner's monomer data: at 10⁵ monomers those arrays and the table together
/// outgrow the last-level cache, and partners are scattered.
#[inline(always)]
pub fn prefetch_partners_ahead(
    rows: &[PairContact],
    slots: usize,
    counts: &[u32],
    k: usize,
    request: impl Fn(usize),
) {
    let ahead = k + PARTNERS_AHEAD;
    if let Some(&count) = counts.get(ahead) {
        for c in &rows[ahead * slots..ahead * slots + count as usize] {
            request(c.partner as usize);
        }
    }
}

/// Prefetches the line holding `item`.
#[inline(always)]
pub fn prefetch_one<T>(item: &T) {
    prefetch(std::slice::from_ref(item));
}
