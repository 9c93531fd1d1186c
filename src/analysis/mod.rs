//! Post-processing of simulation output.
pub mod average;
pub mod ensemble;
pub mod envelope;
pub mod fit;
pub mod front;
pub mod law_checks;
pub mod per_speed;
pub mod regimes;
pub mod run_files;
pub mod speed_laws;
pub mod transient;
