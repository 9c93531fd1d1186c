//! Post-processing of simulation output.
pub mod fit;
