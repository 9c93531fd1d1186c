//! Everything a run writes, from the state and rows it is handed: CSV tables, the checkpoint
//! container, snapshots (VTU, LAMMPS dump, walls, `.pvd` series), SVG plots, the run directory
//! and its bookkeeping, atomic writes.

pub mod atomic;
pub mod checkpoint;
pub mod csv;
pub mod plot;
pub mod run_dir;
pub mod snapshot;
