//! Where each owner's contacts sit in the per-contact results, and for each monomer which of
//! those results it is the partner of: the index `forces` and `wall_forces` gather by,
//! rebuilt after every step with a contact event.
//!
//! Under compression nearly every step has events, so the rebuild runs every step; done on
//! one thread, reading the table's 64-byte contacts twice, it took about a tenth of a
//! two-thread step of a compressed 10⁴ sample (DESIGN.md, "CPU engine: the partner index").
//! It now reads the table once, in parallel, into a compact array of partners, and then
//! counts and places the contacts by ranges of partners, one range per thread: each range
//! owns its part of the output, so the index is the same for any number of ranges.

use super::workspace::{chunk_offsets, split_at_offsets, CHUNK, SERIAL_BELOW};
use crate::state::ContactTable;
use rayon::prelude::*;

/// Compressed sparse rows: the owners' contacts one after another in owner and slot order
/// (`owner_start`), and per partner the positions of its contacts in that order, ascending.
///
/// The results are compact rather than one per slot: at 10⁵ monomers 12 slots of 96 B per
/// owner for about one contact spread 19 MB of results over 115 MB (DESIGN.md, "CPU engine:
/// prefetching contact rows").
#[derive(Clone, Debug, Default)]
pub struct PartnerIndex {
    owner_start: Vec<u32>,
    start: Vec<u32>,
    slots: Vec<u32>,
    /// Each contact's partner, in owner and slot order (kept to reuse its allocation).
    partner: Vec<u32>,
}

impl PartnerIndex {
    /// Heap bytes of the index's arrays.
    pub fn heap_bytes(&self) -> u64 {
        [&self.owner_start, &self.start, &self.slots, &self.partner]
            .iter()
            .map(|v| super::memory::bytes(v))
            .sum()
    }

    /// Rebuilds the index from the table.
    pub fn rebuild(&mut self, table: &ContactTable) {
        let n = table.pair_count.len();
        self.owner_start.clear();
        self.owner_start.push(0);
        let mut total = 0;
        for &count in &table.pair_count {
            total += count;
            self.owner_start.push(total);
        }
        gather_partners(table, &self.owner_start, &mut self.partner);
        let ranges = partner_ranges(n);
        self.start.clear();
        self.start.resize(n + 1, 0);
        count_by_partner(&self.partner, &ranges, &mut self.start[1..]);
        for j in 0..n {
            self.start[j + 1] += self.start[j];
        }
        self.slots.clear();
        self.slots.resize(total as usize, 0);
        place_by_partner(&self.partner, &ranges, &self.start, &mut self.slots);
    }

    /// Positions in the per-contact results whose partner is monomer `j`.
    pub fn of(&self, j: usize) -> &[u32] {
        &self.slots[self.start[j] as usize..self.start[j + 1] as usize]
    }

    /// Where owner `i`'s results begin (`n + 1` entries; the last is the number of contacts).
    pub fn owner_start(&self) -> &[u32] {
        &self.owner_start
    }
}

/// Boundaries of the partner ranges over `0..n`: one range per thread, or one below
/// [`SERIAL_BELOW`] monomers.
fn partner_ranges(n: usize) -> Vec<usize> {
    let count = if n < SERIAL_BELOW {
        1
    } else {
        rayon::current_num_threads().clamp(1, n)
    };
    (0..=count).map(|r| r * n / count).collect()
}

/// Every contact's partner, in owner and slot order, into `partner` (owners in parallel).
fn gather_partners(table: &ContactTable, owner_start: &[u32], partner: &mut Vec<u32>) {
    let n = table.pair_count.len();
    let ps = table.pair_slots;
    partner.clear();
    partner.resize(owner_start[n] as usize, 0);
    let stretches = split_at_offsets(partner, chunk_offsets(owner_start));
    let min_len = if n < SERIAL_BELOW { usize::MAX } else { 1 };
    table
        .pair
        .par_chunks(CHUNK * ps)
        .zip(table.pair_count.par_chunks(CHUNK))
        .zip(stretches.into_par_iter())
        .with_min_len(min_len)
        .for_each(|((rows, counts), out)| {
            let mut out = out.iter_mut();
            for (row, &count) in rows.chunks(ps).zip(counts) {
                for c in &row[..count as usize] {
                    *out.next().expect("a place per contact") = c.partner;
                }
            }
        });
}

/// `counts[j]` = how many contacts have partner `j`: each range counts its own partners.
fn count_by_partner(partner: &[u32], ranges: &[usize], counts: &mut [u32]) {
    split_at_offsets(counts, ranges.iter().copied())
        .into_par_iter()
        .enumerate()
        .for_each(|(r, counts)| {
            let (a, b) = (ranges[r] as u32, ranges[r + 1] as u32);
            for &j in partner {
                if (a..b).contains(&j) {
                    counts[(j - a) as usize] += 1;
                }
            }
        });
}

/// Places each contact's position under its partner, ascending: each range fills the part of
/// `slots` its partners own (`start[a]..start[b]`), reading the contacts in order.
fn place_by_partner(partner: &[u32], ranges: &[usize], start: &[u32], slots: &mut [u32]) {
    let parts = split_at_offsets(slots, ranges.iter().map(|&j| start[j] as usize));
    parts.into_par_iter().enumerate().for_each(|(r, part)| {
        let (a, b) = (ranges[r], ranges[r + 1]);
        let base = start[a];
        let mut next: Vec<u32> = start[a..b].iter().map(|s| s - base).collect();
        for (position, &j) in partner.iter().enumerate() {
            if (a..b).contains(&(j as usize)) {
                let at = &mut next[j as usize - a];
                part[*at as usize] = position as u32;
                *at += 1;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::PairContact;

    /// A table of `n` monomers whose owner `i` has partners `partners(i)`.
    fn table(n: usize, partners: impl Fn(usize) -> Vec<u32>) -> ContactTable {
        let mut t = ContactTable::new(n, 4, 1);
        for i in 0..n {
            for (s, j) in partners(i).into_iter().enumerate() {
                t.pair[i * 4 + s] = PairContact {
                    partner: j,
                    ..t.pair[i * 4 + s]
                };
                t.pair_count[i] += 1;
            }
        }
        t
    }

    #[test]
    fn a_small_table_by_hand() {
        // Owner 0: partners 2, 1; owner 1: partner 2; owner 2: none; owner 3: partner 2.
        let rows = [vec![2, 1], vec![2], vec![], vec![2]];
        let mut index = PartnerIndex::default();
        index.rebuild(&table(4, |i| rows[i].clone()));
        assert_eq!(index.owner_start(), [0, 2, 3, 3, 4]);
        let of: Vec<&[u32]> = (0..4).map(|j| index.of(j)).collect();
        assert_eq!(of, [&[][..], &[1], &[0, 2, 3], &[]]);
        // Owner starts and partner starts 5 entries each, slots and partners 4: 18 × 4 B.
        assert!(index.heap_bytes() >= 72, "{} B", index.heap_bytes());
    }

    #[test]
    fn any_number_of_threads_gives_the_index_of_the_definition() {
        // Enough monomers for the parallel ranges; partners scattered over the whole range.
        let n = 3 * SERIAL_BELOW + 17;
        let partners = |i: usize| -> Vec<u32> {
            let k = (i * 7919 + 13) % 5;
            (1..=k)
                .map(|s| ((i * 104_729 + s * 7_727) % n) as u32)
                .collect()
        };
        let t = table(n, partners);
        // The definition: positions counted in owner and slot order, grouped by partner.
        let mut expected = vec![vec![]; n];
        let mut position = 0u32;
        for i in 0..n {
            for j in partners(i) {
                expected[j as usize].push(position);
                position += 1;
            }
        }
        for threads in [1, 2, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut index = PartnerIndex::default();
            pool.install(|| index.rebuild(&t));
            assert_eq!(index.owner_start()[n], position, "{threads} threads");
            for (j, e) in expected.iter().enumerate() {
                assert_eq!(index.of(j), &e[..], "partner {j}, {threads} threads");
            }
        }
    }
}
