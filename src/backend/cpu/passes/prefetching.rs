//! When the passes prefetch (prefetch.rs holds the hints): by the bytes of the contact table
//! and the per-contact results they walk.

use crate::backend::cpu::law::results::PairResult;
use crate::backend::cpu::prefetch::Prefetching;
use crate::state::{ContactTable, PairContact};

/// Contact-table plus per-slot-result bytes from which the passes prefetch: the size of the
/// last-level cache of the 2-core EPYC the choice was measured on (32 MiB). Below it the rows
/// are in cache anyway and the hints cost: at 10⁴ monomers (19 MB) they made the forces pass
/// 8 % slower; at 10⁵ (190 MB) they make every pass up to twice as fast.
pub const FROM_BYTES: usize = 32 << 20;

/// Whether the passes over `table` prefetch partners' data, and the scan at all (the answer
/// changes no result, only the speed).
pub fn worthwhile(table: &ContactTable) -> bool {
    let per_slot = std::mem::size_of::<PairContact>() + std::mem::size_of::<PairResult>();
    table.pair.len() * per_slot >= FROM_BYTES
}

/// Contact-table bytes from which the per-contact passes prefetch rows: beyond a second-level
/// cache (1 MiB on the EPYC measured). At 10⁴ monomers (7.7 MB, in the last-level cache) the
/// rows alone made the pairs pass 16 % and the forces pass 22 % faster, where rows and
/// partners together had made them slower (the partners' indices are loads, not hints).
pub const ROWS_FROM_BYTES: usize = 1 << 20;

/// What `integrate_pairs` and `forces` prefetch over `table`.
pub fn for_contact_passes(table: &ContactTable) -> Prefetching {
    if worthwhile(table) {
        Prefetching::RowsAndPartners
    } else if std::mem::size_of_val(&table.pair[..]) >= ROWS_FROM_BYTES {
        Prefetching::Rows
    } else {
        Prefetching::Off
    }
}
