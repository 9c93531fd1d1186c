//! Contact maintenance pass, the twin of `contacts` in shaders/passes/contacts.wgsl: for the
//! owners `contacts_scan` listed, breaks stretched contacts (δ < −δ_c) and forms new ones
//! (δ ≥ 0), keeping the history (pointers, twist, wall anchor) of every contact that persists;
//! then applies the inelastic limits of their pair contacts and evaluates their wall contacts
//! (limits and forces, into the per-slot results `wall_forces` gathers).
//!
//! Every change is to the owner's own row of the table, so owners run in parallel (in fixed
//! chunks, each summing its dissipation in owner order); a row's events are the same whatever
//! the thread count.

use super::neighbours::NeighbourList;
use super::scan::{RowsFrom, Scan};
use crate::backend::cpu::chunking::{split_len, sum_in_order, CHUNK};
use crate::backend::cpu::lanes::ContactLanes;
use crate::backend::cpu::law::corrections_lanes::chunk_corrections;
use crate::backend::cpu::law::forces_lanes::radius_ratios;
use crate::backend::cpu::law::results::WallResult;
use crate::backend::cpu::law::walls::wall_contacts_of;
use crate::backend::cpu::partner_index::RowChange;
use crate::backend::cpu::workspace::Workspace;
use crate::backend::script::{OWNER_CORRECTIONS, OWNER_EVENTS, OWNER_INDEX, OWNER_WALLS};
use crate::engine::EngineError;
use crate::model::{wall as wall_law, ContactLaw};
use crate::state::interaction::{pair_step_energy, wall_overlap_ratio, wall_step_energy};
use crate::state::{
    ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact, MAX_PAIR_SLOTS,
};
use rayon::prelude::*;

/// One owner's row of the table.
struct Row<'a> {
    pair: &'a mut [PairContact],
    pair_count: &'a mut u32,
    wall: &'a mut [WallContact],
    wall_count: &'a mut u32,
}

/// The work items of the owners `first..first + len` in a list sorted by owner.
fn items_of(work: &[u32], first: usize, len: usize) -> &[u32] {
    let a = work.partition_point(|w| ((w & OWNER_INDEX) as usize) < first);
    let b = work.partition_point(|w| ((w & OWNER_INDEX) as usize) < first + len);
    &work[a..b]
}

/// What every owner's work reads.
struct Shared<'a> {
    law: &'a ContactLaw,
    dt: f64,
    monomers: &'a Monomers,
    walls: &'a [Wall],
    candidates: &'a [(u32, u32)],
    starts: &'a [u32],
    /// Whether the tally books the pair and the wall corrections (their channels not NaN).
    books: (bool, bool),
    /// The table's pair and wall slots per owner.
    slots: (usize, usize),
}

/// Does what `work` (contacts_scan's list) says for each listed owner: its contact events
/// (`candidates` are the neighbour-list pairs, i < j, sorted; `starts` where each owner's
/// begin, [`super::neighbours::owner_starts`]), its pair contacts' inelastic limits, its wall
/// contacts' limits and forces (into `workspace`'s per-slot wall results). Returns the owners
/// whose pair row a contact forming or breaking changed, by ascending owner, with their
/// partners before (for the partner index; wall contacts do not move its entries).
#[allow(clippy::too_many_arguments)]
pub fn contacts(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    walls: &[Wall],
    candidates: &[(u32, u32)],
    starts: &[u32],
    table: &mut ContactTable,
    tally: &mut Dissipation,
    work: &[u32],
    workspace: &mut Workspace,
) -> Result<Vec<RowChange>, EngineError> {
    let shared = Shared::new(
        (law, dt),
        monomers,
        walls,
        (candidates, starts),
        table,
        tally,
    );
    let lanes = ContactLanes::chosen();
    // Owners are few and far between in the list, so rows are not prefetched here.
    let chunks = over_chunks(table, workspace, |chunk, rows| {
        let items = items_of(work, chunk * CHUNK, rows.1.len());
        chunk_work(&shared, lanes, chunk, rows, items)
    });
    sum_chunks(chunks, tally)
}

/// The step's `contacts_scan` and `contacts` in one parallel sweep: each chunk's owners
/// scanned, then the chunk's listed owners' work done at once, while the rows are at hand.
/// A chunk's scan reads only its own owners' rows, and a chunk's work changes only its own
/// owners' rows, so every scan sees the rows before the events, as in the passes one after
/// the other: the same work list (left in `workspace.work`), rows and tally.
pub fn contacts_scanned(
    (law, dt): (&ContactLaw, f64),
    monomers: &Monomers,
    walls: &[Wall],
    list: &mut NeighbourList,
    table: &mut ContactTable,
    tally: &mut Dissipation,
    workspace: &mut Workspace,
) -> Result<Vec<RowChange>, EngineError> {
    let scan = Scan::new(law, monomers, walls, list, table);
    let list = scan.list();
    let candidates = (&list.pairs[..], &list.starts[..]);
    let shared = Shared::new((law, dt), monomers, walls, candidates, table, tally);
    let (lanes, slots) = (ContactLanes::chosen(), shared.slots);
    let pair_tests = std::mem::take(&mut workspace.pair_tests);
    let chunks = over_chunks(table, workspace, |chunk, rows| {
        let before = (&*rows.0, &*rows.1, &*rows.2, &*rows.3);
        let before = RowsFrom::chunk(chunk * CHUNK, before, slots);
        let items = scan.chunk(&before, &pair_tests, chunk);
        chunk_work(&shared, lanes, chunk, rows, &items).map(|done| (done, items))
    });
    workspace.pair_tests = pair_tests;
    let mut done = Vec::with_capacity(chunks.len());
    workspace.work.clear();
    for c in chunks {
        done.push(c.map(|(d, items)| {
            workspace.work.extend(items);
            d
        }));
    }
    sum_chunks(done, tally)
}

impl<'a> Shared<'a> {
    /// What every owner's work reads (`candidates`: the neighbour-list pairs and where each
    /// owner's begin); `table` must have at most [`MAX_PAIR_SLOTS`] pair slots.
    fn new(
        (law, dt): (&'a ContactLaw, f64),
        monomers: &'a Monomers,
        walls: &'a [Wall],
        (candidates, starts): (&'a [(u32, u32)], &'a [u32]),
        table: &ContactTable,
        tally: &Dissipation,
    ) -> Self {
        let (ps, ws) = (table.pair_slots, table.wall_slots);
        assert!(
            ps <= MAX_PAIR_SLOTS,
            "{ps} pair slots, at most {MAX_PAIR_SLOTS}"
        );
        Shared {
            law,
            dt,
            monomers,
            walls,
            candidates,
            starts,
            books: (
                tally.books_pair_corrections(),
                tally.books_wall_corrections(),
            ),
            slots: (ps, ws),
        }
    }
}

/// `work` on each chunk of owners (its index and its rows of the table and wall results, the
/// results sized first), in parallel; the chunks' outcomes in chunk order.
fn over_chunks<R: Send>(
    table: &mut ContactTable,
    workspace: &mut Workspace,
    work: impl Fn(usize, ChunkRows) -> R + Sync,
) -> Vec<R> {
    let (ps, ws, n) = (table.pair_slots, table.wall_slots, table.pair_count.len());
    workspace.size_wall_results(n * ws);
    (
        table.pair.par_chunks_mut(CHUNK * ps),
        table.pair_count.par_chunks_mut(CHUNK),
        table.wall.par_chunks_mut(CHUNK * ws),
        table.wall_count.par_chunks_mut(CHUNK),
        workspace.wall_result.par_chunks_mut(CHUNK * ws),
    )
        .into_par_iter()
        .with_min_len(split_len(n, CHUNK))
        .enumerate()
        .map(|(chunk, rows)| work(chunk, rows))
        .collect()
}

/// The chunks' tallies added to `tally` in chunk order; the changed rows, by ascending owner.
fn sum_chunks(
    chunks: Vec<Result<(Dissipation, Vec<RowChange>), EngineError>>,
    tally: &mut Dissipation,
) -> Result<Vec<RowChange>, EngineError> {
    let mut sums = Vec::with_capacity(chunks.len());
    let mut changed = Vec::new();
    for c in chunks {
        let (sum, c) = c?;
        sums.push(sum);
        changed.extend(c);
    }
    tally.add(&sum_in_order(&sums));
    Ok(changed)
}

/// One chunk's rows of the table (pairs, pair counts, walls, wall counts) and its wall results.
type ChunkRows<'a> = (
    &'a mut [PairContact],
    &'a mut [u32],
    &'a mut [WallContact],
    &'a mut [u32],
    &'a mut [WallResult],
);

/// What `items` (the work items of chunk `chunk`'s owners) say, for each listed owner in
/// order: its work, then the corrections; what the chunk dissipated and the rows it changed.
fn chunk_work(
    shared: &Shared,
    lanes: ContactLanes,
    chunk: usize,
    (pairs, pair_counts, wall_rows, wall_counts, results): ChunkRows,
    items: &[u32],
) -> Result<(Dissipation, Vec<RowChange>), EngineError> {
    let (law, dt, monomers) = (shared.law, shared.dt, shared.monomers);
    let (ps, ws) = shared.slots;
    let mut dissipated = Dissipation::default();
    let mut changed = Vec::new();
    let first = chunk * CHUNK;
    let wall_rows_of = |k: usize| &wall_rows[k * ws..k * ws + wall_counts[k] as usize];
    let known = known_ratios(shared, lanes, items, first, ws, wall_rows_of);
    for (at, &item) in items.iter().enumerate() {
        let k = (item & OWNER_INDEX) as usize - first;
        let mut row = Row {
            pair: &mut pairs[k * ps..(k + 1) * ps],
            pair_count: &mut pair_counts[k],
            wall: &mut wall_rows[k * ws..(k + 1) * ws],
            wall_count: &mut wall_counts[k],
        };
        let results = &mut results[k * ws..(k + 1) * ws];
        let known = &known[at * ws..(at + 1) * ws];
        let walls = (results, known);
        let change = owner_work(shared, item, &mut row, walls, &mut dissipated)?;
        changed.extend(change);
    }
    // After the events, which may add contacts the corrections then see; the corrections
    // book only their own channels, so their order against the events' and walls' bookings
    // does not matter.
    let corrected = items.iter().filter(|w| *w & OWNER_CORRECTIONS != 0);
    let rows = pairs.chunks_mut(ps).zip(pair_counts.iter()).enumerate();
    let mut rows = rows.map(|(k, (row, &count))| (first + k, &mut row[..count as usize]));
    let owners = corrected.map(|w| {
        let i = (w & OWNER_INDEX) as usize;
        rows.find(|(owner, _)| *owner == i)
            .expect("a listed owner's row")
    });
    let booked = shared.books.0.then_some(&mut dissipated);
    chunk_corrections(lanes, law, dt, monomers, owners, booked);
    Ok((dissipated, changed))
}

/// The contact radius ratio of each wall contact the listed owners with wall work (`items`,
/// of the chunk from owner `first`) have before their events, per item `ws` slots of (wall,
/// ratio), found four at a time (the JKR inversion is most of a wall contact's arithmetic);
/// they depend on the monomer and the wall only, so a contact the events leave in its slot
/// uses its own. Empty slots hold no wall.
fn known_ratios<'a>(
    s: &Shared,
    lanes: ContactLanes,
    items: &[u32],
    first: usize,
    ws: usize,
    wall_rows_of: impl Fn(usize) -> &'a [WallContact],
) -> Vec<(u32, f64)> {
    let mut known = vec![(u32::MAX, 0.0); items.len() * ws];
    let mut ratios = Vec::new();
    for &item in items.iter().filter(|w| *w & OWNER_WALLS != 0) {
        let i = (item & OWNER_INDEX) as usize;
        for c in wall_rows_of(i - first) {
            let x = s.monomers.position[i];
            ratios.push(wall_overlap_ratio(s.law, x, &s.walls[c.wall as usize]));
        }
    }
    radius_ratios(lanes, &mut ratios);
    let mut ratios = ratios.into_iter();
    for (at, &item) in items.iter().enumerate() {
        if item & OWNER_WALLS == 0 {
            continue;
        }
        let i = (item & OWNER_INDEX) as usize;
        for (slot, c) in wall_rows_of(i - first).iter().enumerate() {
            let x = ratios.next().expect("a ratio per wall contact");
            known[at * ws + slot] = (c.wall, x);
        }
    }
    known
}

/// One listed owner's work, in the device's order: events, limits, wall contacts. Returns
/// its pair row as it was, where a pair contact formed or broke.
fn owner_work(
    s: &Shared,
    item: u32,
    row: &mut Row,
    (wall_results, known): (&mut [WallResult], &[(u32, f64)]),
    dissipated: &mut Dissipation,
) -> Result<Option<RowChange>, EngineError> {
    let i = (item & OWNER_INDEX) as usize;
    let mut changed = None;
    if item & OWNER_EVENTS != 0 {
        let mine = &s.candidates[s.starts[i] as usize..s.starts[i + 1] as usize];
        // The row as it was, kept on the stack: most events change no pair row.
        let count = *row.pair_count as usize;
        let mut before = [0u32; MAX_PAIR_SLOTS];
        for (b, c) in before.iter_mut().zip(&row.pair[..count]) {
            *b = c.partner;
        }
        if contact_events(s.law, s.dt, s.monomers, s.walls, mine, i, row, dissipated)? {
            changed = Some(RowChange {
                owner: i as u32,
                partners_before: before[..count].to_vec(),
            });
        }
    }
    if item & OWNER_WALLS != 0 {
        let count = *row.wall_count as usize;
        wall_contacts_of(
            s.law,
            s.dt,
            s.walls,
            s.monomers,
            i,
            &mut row.wall[..count],
            (&mut wall_results[..count], known),
            s.books.1.then_some(dissipated),
        );
    }
    Ok(changed)
}

/// Breaks, then forms, the pair and wall contacts of owner `i` (`candidates` are its own);
/// returns whether any pair contact formed or broke.
#[allow(clippy::too_many_arguments)]
fn contact_events(
    law: &ContactLaw,
    dt: f64,
    monomers: &Monomers,
    walls: &[Wall],
    candidates: &[(u32, u32)],
    i: usize,
    row: &mut Row,
    tally: &mut Dissipation,
) -> Result<bool, EngineError> {
    let r = law.radius;
    let count_before = *row.pair_count;
    let mut broke = false;
    let pos = &monomers.position;
    // Break.
    let mut slot = 0;
    while slot < *row.pair_count as usize {
        let c = row.pair[slot];
        let delta = 2.0 * r - (pos[i] - pos[c.partner as usize]).length();
        if delta < -law.pair.delta_c {
            tally.breaking += pair_step_energy(law, monomers, dt, i, &c);
            broke = true;
            row.pair[slot] = row.pair[*row.pair_count as usize - 1];
            *row.pair_count -= 1;
        } else {
            slot += 1;
        }
    }
    let mut slot = 0;
    while slot < *row.wall_count as usize {
        let c = row.wall[slot];
        let w = &walls[c.wall as usize];
        let delta = wall_law::wall_overlap(pos[i], w.point, w.normal, r);
        if delta < -w.constants.delta_c {
            tally.walls += wall_step_energy(law, monomers, dt, i, w, &c);
            row.wall[slot] = row.wall[*row.wall_count as usize - 1];
            *row.wall_count -= 1;
        } else {
            slot += 1;
        }
    }
    // Form.
    for &(_, j) in candidates {
        let d = pos[i] - pos[j as usize];
        let distance = d.length();
        let count = *row.pair_count as usize;
        if 2.0 * r - distance < 0.0 || row.pair[..count].iter().any(|c| c.partner == j) {
            continue;
        }
        if count >= row.pair.len() {
            return Err(EngineError::SlotOverflow {
                kind: "monomer-monomer",
                step: 0,
                monomer: i,
                limit: row.pair.len(),
            });
        }
        let nc = d / distance;
        let c = PairContact {
            partner: j,
            n1: -nc,
            n2: nc,
            twist: 0.0,
        };
        tally.forming -= pair_step_energy(law, monomers, dt, i, &c);
        row.pair[count] = c;
        *row.pair_count += 1;
    }
    for (w_idx, w) in walls.iter().enumerate() {
        let w_id = w_idx as u32;
        let count = *row.wall_count as usize;
        if wall_law::wall_overlap(pos[i], w.point, w.normal, r) < 0.0
            || row.wall[..count].iter().any(|c| c.wall == w_id)
        {
            continue;
        }
        if count >= row.wall.len() {
            return Err(EngineError::SlotOverflow {
                kind: "monomer-wall",
                step: 0,
                monomer: i,
                limit: row.wall.len(),
            });
        }
        let c = WallContact {
            wall: w_id,
            n1: -w.normal,
            anchor: pos[i] - w.normal * r,
            twist: 0.0,
        };
        tally.walls -= wall_step_energy(law, monomers, dt, i, w, &c);
        row.wall[count] = c;
        *row.wall_count += 1;
    }
    Ok(broke || count_before != *row.pair_count)
}
