//! Experiments: setups, wall motion, measurements and stop rules.

pub mod collision;
pub mod compression;
pub mod measure;
pub mod setup;
