//! Output files: figures, tables, atomic writes.
pub mod atomic;
pub mod csv;
pub mod plot;
