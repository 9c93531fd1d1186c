//! Where each owner's contacts sit in the per-contact results, and for each monomer which of
//! those results it is the partner of: the index `forces` and `wall_forces` gather by.
//!
//! Each monomer keeps the contacts it is the partner of as entries `owner << slot_bits | slot`,
//! ascending (owner and slot order, the gather's order), in `room` places of its own; a
//! result's position is `owner_start[owner] + slot`. The owners of one chunk of [`CHUNK`]
//! (the passes' unit of parallel work) hold places in the chunk's own stretch of results,
//! which keeps some spare places at its end ([`spare_results`]): a rebuild lays them out one
//! after another, and a row that contact events made longer takes new places from the spare
//! ones. So an event touches only the entries of the partners of the rows it changed and
//! those rows' places ([`PartnerIndex::update`]); every other owner's results stay where they
//! are, and the CPU step keeps them from its pairs pass (docs/guide/src/benchmarks.md, "CPU
//! engine: the forces where the pointers are"). Under compression nearly every step has events
//! but few rows change (23 of 10⁴ rows per step at φ 0.45): the full rebuild after each such
//! step had been 7 % of a one-thread step's instructions (docs/guide/src/benchmarks.md, "CPU
//! engine: the partner index"; DESIGN.md, "The CPU engine on many cores"). The
//! full rebuild remains for a new or replaced table, for a monomer whose entries outgrow their
//! room, and for a chunk whose spare places are used up.

use super::chunking::CHUNK;
use super::memory::bytes;
use crate::state::ContactTable;

/// Spare places per monomer beyond the most entries any monomer had at the full rebuild, so
/// that a contact forming does not force another rebuild at once.
const SPARE_ROOM: usize = 2;

/// Spare places at the end of a chunk's stretch of results holding `contacts`: an eighth more,
/// and at least 8, so that the contacts formed over many steps fit before a rebuild.
pub fn spare_results(contacts: u32) -> u32 {
    contacts / 8 + 8
}

/// An owner's pair row before the contact events changed it: its partners by slot.
#[derive(Clone, Debug, PartialEq)]
pub struct RowChange {
    pub owner: u32,
    pub partners_before: Vec<u32>,
}

/// Per monomer the contacts it is the partner of, and per owner where its results begin.
#[derive(Clone, Debug, Default)]
pub struct PartnerIndex {
    owner_start: Vec<u32>,
    /// Low bits of an entry holding the slot.
    slot_bits: u32,
    /// Places per monomer in `entries`.
    room: usize,
    /// Monomer `j`'s entries are `entries[j * room..j * room + count[j]]`, ascending.
    entries: Vec<u32>,
    count: Vec<u32>,
    /// Where each chunk's stretch of results begins (one more entry: the end of the last).
    chunk_base: Vec<u32>,
    /// Per chunk the first place of its stretch no owner holds: where a row that grew goes.
    chunk_free: Vec<u32>,
}

impl PartnerIndex {
    /// Heap bytes of the index's arrays.
    pub fn heap_bytes(&self) -> u64 {
        [
            &self.owner_start,
            &self.entries,
            &self.count,
            &self.chunk_base,
            &self.chunk_free,
        ]
        .iter()
        .map(|v| bytes(v))
        .sum()
    }

    /// Rebuilds the index from the table: the entries counted per partner, the room set by
    /// the most of them, then placed owner by owner and slot by slot (so ascending).
    pub fn rebuild(&mut self, table: &ContactTable) {
        let n = table.pair_count.len();
        let ps = table.pair_slots;
        self.slot_bits = usize::BITS - (ps.max(2) - 1).leading_zeros();
        assert!(
            n <= (u32::MAX >> self.slot_bits) as usize,
            "{n} monomers with {ps} pair slots each do not fit the partner index's 32-bit entries"
        );
        self.count.clear();
        self.count.resize(n, 0);
        for i in 0..n {
            for c in table.pairs_of(i) {
                self.count[c.partner as usize] += 1;
            }
        }
        self.room = self.count.iter().max().map_or(0, |&m| m as usize) + SPARE_ROOM;
        self.count.fill(0);
        self.entries.clear();
        self.entries.resize(n * self.room, 0);
        for i in 0..n {
            for (s, c) in table.pairs_of(i).iter().enumerate() {
                let j = c.partner as usize;
                self.entries[j * self.room + self.count[j] as usize] = self.entry(i, s);
                self.count[j] += 1;
            }
        }
        self.owner_start.clear();
        self.owner_start.resize(n + 1, 0);
        self.chunk_base.clear();
        self.chunk_free.clear();
        let mut start = 0;
        for first in (0..n).step_by(CHUNK) {
            self.chunk_base.push(start);
            let mut contacts = 0;
            for i in first..(first + CHUNK).min(n) {
                self.owner_start[i] = start + contacts;
                contacts += table.pair_count[i];
            }
            self.chunk_free.push(start + contacts);
            start += contacts + spare_results(contacts);
        }
        self.chunk_base.push(start);
        self.owner_start[n] = start;
    }

    /// Brings the index up to date after contact events changed the rows `changes` lists (by
    /// ascending owner, each with its partners before): the old rows' entries removed, the new
    /// rows' inserted in order, and a row that grew given new places at the free end of its
    /// chunk's stretch (one that did not grow keeps its places). No other owner's results
    /// move, unless the chunk's spare places run out: the chunk is then laid out afresh, its
    /// unchanged rows' `results` moved with their places ([`Self::compact_chunk`]). Returns
    /// false, the index then stale, where a monomer's entries outgrew their room or a chunk's
    /// contacts outgrew its stretch: rebuild it.
    pub fn update<T: Copy>(
        &mut self,
        table: &ContactTable,
        changes: &[RowChange],
        results: &mut [T],
    ) -> bool {
        for change in changes {
            let i = change.owner as usize;
            for (s, &j) in change.partners_before.iter().enumerate() {
                self.remove(j as usize, self.entry(i, s));
            }
        }
        let mut compacted = None;
        for (k, change) in changes.iter().enumerate() {
            let i = change.owner as usize;
            for (s, c) in table.pairs_of(i).iter().enumerate() {
                if !self.insert(c.partner as usize, self.entry(i, s)) {
                    return false;
                }
            }
            let (count, chunk) = (table.pair_count[i], i / CHUNK);
            if count as usize <= change.partners_before.len() || compacted == Some(chunk) {
                continue;
            }
            if self.chunk_free[chunk] + count > self.chunk_base[chunk + 1] {
                // Every row of the chunk still to come is in `changes[k..]`.
                if !self.compact_chunk(table, chunk, &changes[k..], results) {
                    return false;
                }
                compacted = Some(chunk);
                continue;
            }
            self.owner_start[i] = self.chunk_free[chunk];
            self.chunk_free[chunk] += count;
        }
        true
    }

    /// Lays the owners of `chunk` out one after another again (the holes the rows that grew
    /// left behind closed), the `results` of those not in `changes` moved to their new places;
    /// false where its contacts do not fit its stretch.
    fn compact_chunk<T: Copy>(
        &mut self,
        table: &ContactTable,
        chunk: usize,
        changes: &[RowChange],
        results: &mut [T],
    ) -> bool {
        let n = table.pair_count.len();
        let owners = chunk * CHUNK..((chunk + 1) * CHUNK).min(n);
        let (base, end) = (self.chunk_base[chunk], self.chunk_base[chunk + 1]);
        let total: u32 = table.pair_count[owners.clone()].iter().sum();
        if base + total > end {
            return false;
        }
        let moving = results.len() >= end as usize;
        let before = if moving {
            results[base as usize..end as usize].to_vec()
        } else {
            Vec::new()
        };
        let changed = |i: usize| changes.iter().any(|c| c.owner as usize == i);
        let mut free = base;
        for i in owners {
            let (was, count) = (self.owner_start[i], table.pair_count[i]);
            self.owner_start[i] = free;
            if moving && !changed(i) {
                let from = (was - base) as usize..(was - base + count) as usize;
                let to = free as usize;
                results[to..to + count as usize].copy_from_slice(&before[from]);
            }
            free += count;
        }
        self.chunk_free[chunk] = free;
        true
    }

    fn entry(&self, owner: usize, slot: usize) -> u32 {
        (owner as u32) << self.slot_bits | slot as u32
    }

    fn remove(&mut self, j: usize, entry: u32) {
        let list = &mut self.entries[j * self.room..j * self.room + self.count[j] as usize];
        let at = list
            .binary_search(&entry)
            .expect("a changed row's old contact is in its partner's entries");
        list.copy_within(at + 1.., at);
        self.count[j] -= 1;
    }

    /// Inserts in order; false where the monomer's room is full.
    fn insert(&mut self, j: usize, entry: u32) -> bool {
        let count = self.count[j] as usize;
        if count == self.room {
            return false;
        }
        let list = &mut self.entries[j * self.room..j * self.room + count + 1];
        let at = list[..count].partition_point(|&e| e < entry);
        list.copy_within(at..count, at + 1);
        list[at] = entry;
        self.count[j] += 1;
        true
    }

    /// Positions in the per-contact results whose partner is monomer `j`, ascending.
    pub fn of(&self, j: usize) -> impl Iterator<Item = u32> + '_ {
        let mask = (1u32 << self.slot_bits) - 1;
        let entries = &self.entries[j * self.room..j * self.room + self.count[j] as usize];
        entries
            .iter()
            .map(move |&e| self.owner_start[(e >> self.slot_bits) as usize] + (e & mask))
    }

    /// The contacts monomer `j` is the partner of, as (owner, slot), in the gather's order.
    pub fn contacts_of_partner(&self, j: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let mask = (1u32 << self.slot_bits) - 1;
        let entries = &self.entries[j * self.room..j * self.room + self.count[j] as usize];
        entries
            .iter()
            .map(move |&e| ((e >> self.slot_bits) as usize, (e & mask) as usize))
    }

    /// Whether the owners' results are laid out as the gather needs for `table`: each owner's
    /// places within its chunk's stretch and below the stretch's free end, no two owners'
    /// overlapping. Where not, says which owner is out of place.
    pub fn check_layout(&self, table: &ContactTable) -> Result<(), String> {
        let n = table.pair_count.len();
        let chunks = n.div_ceil(CHUNK);
        if self.owner_start.len() != n + 1 || self.chunk_base.len() != chunks + 1 {
            return Err(format!("{} starts for {n} owners", self.owner_start.len()));
        }
        for chunk in 0..chunks {
            let first = chunk * CHUNK;
            let mut places: Vec<(u32, u32, usize)> = (first..(first + CHUNK).min(n))
                .filter(|&i| table.pair_count[i] > 0)
                .map(|i| {
                    (
                        self.owner_start[i],
                        self.owner_start[i] + table.pair_count[i],
                        i,
                    )
                })
                .collect();
            places.sort_unstable();
            let mut free_from = self.chunk_base[chunk];
            for (start, end, i) in places {
                if start < free_from || end > self.chunk_free[chunk] {
                    return Err(format!("owner {i}: places {start}..{end} overlap or leave"));
                }
                free_from = end;
            }
        }
        let ends = (self.chunk_free.iter()).zip(&self.chunk_base[1..]);
        match ends.enumerate().find(|(_, (free, end))| free > end) {
            Some((chunk, _)) => Err(format!("chunk {chunk}: free end beyond its stretch")),
            None => Ok(()),
        }
    }

    /// Where each chunk's stretch of results begins, and where the last one ends.
    pub fn chunk_bases(&self) -> &[u32] {
        &self.chunk_base
    }

    /// Where owner `i`'s results begin (`n + 1` entries; the last is the length of the
    /// results, spare places included; owner `i`'s are the `pair_count[i]` from its start).
    pub fn owner_start(&self) -> &[u32] {
        &self.owner_start
    }
}

#[cfg(test)]
mod tests;
