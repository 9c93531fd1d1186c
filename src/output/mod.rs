//! Output files: figures, tables, atomic writes.
pub mod atomic;
pub mod checkpoint;
pub mod csv;
pub mod plot;
pub mod run_dir;
pub mod snapshot;
