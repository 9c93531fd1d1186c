//! dustdem: molecular dynamics of porous dust agglomerates.

pub mod cpu;
pub mod experiment;
pub mod material;
pub mod model;
