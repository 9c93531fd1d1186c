//! dustdem: molecular dynamics of porous dust agglomerates.

pub mod analysis;
pub mod cpu;
pub mod experiment;
pub mod io;
pub mod material;
pub mod model;
pub mod rng;
pub mod sample;
