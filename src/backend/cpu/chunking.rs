//! How the passes split their work: fixed chunks of monomers, so that every sum is the same
//! for any thread count, and the helpers that hand each chunk its own stretch of an output.
//! The bottom layer of the CPU engine with the lanes: it names nothing else of the engine.

use crate::state::Dissipation;

/// Monomers per unit of parallel work. Sums that leave the monomer loop (dissipation, work) are
/// taken per chunk in monomer order and then over chunks in order: the chunks are fixed by this
/// number, not by the threads, so the bits are the same for any thread count.
pub const CHUNK: usize = 512;

/// Below this many monomers every pass runs on the thread that calls it: handing a pass of a
/// few microseconds to another thread costs about as much as the pass (at N = 1000 two
/// threads were no faster than one). The results do not depend on it.
pub const SERIAL_BELOW: usize = 4096;

/// Least items per parallel split of a pass over `n` monomers whose items hold `unit`
/// monomers each: one chunk's worth, or everything where `n` is below [`SERIAL_BELOW`].
pub fn split_len(n: usize, unit: usize) -> usize {
    if n < SERIAL_BELOW {
        usize::MAX
    } else {
        (CHUNK / unit).max(1)
    }
}

/// Splits `items` into consecutive parts, part `k` from `offsets[k]` to `offsets[k + 1]`
/// (offsets ascending, the first 0): how a parallel pass hands each unit its own stretch of an
/// output laid out by owner or by partner.
pub fn split_at_offsets<T>(
    mut items: &mut [T],
    offsets: impl IntoIterator<Item = usize>,
) -> Vec<&mut [T]> {
    let mut offsets = offsets.into_iter();
    let mut at = offsets.next().unwrap_or(0);
    let mut parts = Vec::new();
    for next in offsets {
        let (part, tail) = items.split_at_mut(next - at);
        parts.push(part);
        items = tail;
        at = next;
    }
    parts
}

/// Sums per-chunk tallies in chunk order.
pub fn sum_in_order(chunks: &[Dissipation]) -> Dissipation {
    let mut total = Dissipation::default();
    for c in chunks {
        total.add(c);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_run_from_offset_to_offset() {
        let mut items = [1, 2, 3, 4, 5];
        let parts = split_at_offsets(&mut items, [0, 2, 2, 5]);
        let parts: Vec<&[i32]> = parts.into_iter().map(|p| &*p).collect();
        assert_eq!(parts, [&[1, 2][..], &[], &[3, 4, 5]]);
    }
}
