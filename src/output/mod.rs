//! Everything a run writes, from the state and rows it is handed: CSV tables, the checkpoint
//! container, snapshots (VTU, LAMMPS dump, walls, `.pvd` series), SVG plots, the run directory
//! and its bookkeeping, the lock that gives a directory one owner, atomic writes.

pub mod atomic;
pub mod checkpoint;
pub mod csv;
pub mod lock;
pub mod plot;
pub mod run_dir;
pub mod snapshot;
