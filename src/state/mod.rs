//! The simulation state every backend, checkpoint and snapshot shares.
pub mod contacts;
pub mod reduction;

pub use contacts::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
