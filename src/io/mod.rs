//! Output files: figures and tables.
pub mod csv;
pub mod plot;
