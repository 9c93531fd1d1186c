//! What the CPU engine holds in memory: the bytes of every array of its state, from their
//! capacities; the neighbour list, the partner index and the workspace count theirs with
//! [`bytes`] (`heap_bytes`), and the engine adds them up (`CpuEngine::host_bytes`). The figure
//! a run reports per monomer and the guide states; `tests/memory.rs` holds a run's resident
//! memory to it. A bottom-layer module: it names nothing of the engine.

use crate::state::{ContactTable, Monomers, State};

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

/// Heap bytes of a state's arrays: monomers, contact table, walls' forces.
pub fn state_bytes(s: &State) -> u64 {
    monomer_bytes(&s.monomers)
        + table_bytes(&s.contacts)
        + bytes(&s.wall_force)
        + bytes(&s.wall_damping)
}
