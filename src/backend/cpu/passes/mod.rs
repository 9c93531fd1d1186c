//! The passes of the step script, each the twin of a WGSL entry point of the same name (the
//! executor, executor.rs, runs them): the layer above the contact law. A pass walks the
//! monomers or their contacts in fixed chunks, calls the law per contact or per chunk of
//! owners, and gathers or sums the results in a fixed order.
//!
//! - `integrate.rs`: the leap-frog (kick, pairs, drift);
//! - `neighbours.rs`: the candidate list and the passes that build it;
//! - `scan.rs`: what the contacts pass has to do;
//! - `contacts.rs`: contact events, inelastic limits, wall contacts;
//! - `forces.rs`: the pair contacts' forces;
//! - `walls.rs`: the gather of every monomer's forces, the walls' forces;
//! - `prefetching.rs`: when the per-contact passes prefetch.

pub mod contacts;
pub mod forces;
pub mod integrate;
pub mod neighbours;
pub mod prefetching;
pub mod scan;
pub mod walls;
