//! What the CPU engine holds in memory: the bytes of every array of its state, neighbour list
//! and workspace, from their capacities. The figure a run reports per monomer and the guide
//! states; `tests/memory.rs` holds a run's resident memory to it.

use super::neighbours::NeighbourList;
use super::workspace::Workspace;
use super::CpuEngine;
use crate::state::{ContactTable, Monomers};

/// Heap bytes a vector holds (its capacity, not its length).
pub fn bytes<T>(v: &Vec<T>) -> u64 {
    (v.capacity() * std::mem::size_of::<T>()) as u64
}

fn monomer_bytes(m: &Monomers) -> u64 {
    [
        &m.position,
        &m.velocity,
        &m.angular_velocity,
        &m.force,
        &m.torque,
        &m.damping_force,
    ]
    .iter()
    .map(|v| bytes(v))
    .sum::<u64>()
        + bytes(&m.inverse_mass_scale)
        + bytes(&m.inverse_inertia_scale)
        + bytes(&m.id)
}

fn table_bytes(t: &ContactTable) -> u64 {
    bytes(&t.pair) + bytes(&t.pair_count) + bytes(&t.wall) + bytes(&t.wall_count)
}

fn neighbour_bytes(l: &NeighbourList) -> u64 {
    bytes(&l.pairs) + bytes(&l.starts) + bytes(&l.reference) + bytes(&l.cells)
}

fn workspace_bytes(w: &Workspace) -> u64 {
    bytes(&w.pair_result)
        + w.incoming.heap_bytes()
        + bytes(&w.wall_result)
        + bytes(&w.pair_tests)
        + bytes(&w.work)
        + bytes(&w.wall_partials)
        + bytes(&w.wall_damping_partials)
}

/// Heap bytes of the engine's arrays: monomers, contact table, walls' forces, neighbour list,
/// per-contact results, indices and work lists.
pub fn engine_bytes(e: &CpuEngine) -> u64 {
    let s = &e.state;
    monomer_bytes(&s.monomers)
        + table_bytes(&s.contacts)
        + bytes(&s.wall_force)
        + bytes(&s.wall_damping)
        + neighbour_bytes(&e.neighbours)
        + workspace_bytes(&e.workspace)
}
