//! The backends that step the state: the f64 CPU reference and the WGSL engine, and the step
//! script both run.
pub mod cpu;
pub mod gpu;
pub mod script;
