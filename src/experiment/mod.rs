//! Experiments: setups, wall motion, measurements and stop rules.

pub mod collision;
