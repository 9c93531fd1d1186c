//! The backends that step the state: the f64 CPU reference and the WGSL engine.
pub mod cpu;
pub mod gpu;
