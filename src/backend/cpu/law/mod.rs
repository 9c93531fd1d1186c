//! The contact law as the CPU engine evaluates it, contact by contact: the layer above the
//! lanes and the chunking, below the passes. Each file is one part of the per-contact work,
//! one contact at a time and four at a time in the lanes (the same bits), with the chunk
//! kernels the passes call for a chunk of owners:
//!
//! - `results.rs`: what a contact exerts ([`results::PairResult`], [`results::WallResult`]),
//!   where a chunk's results go and the chunk of owners a pass hands over;
//! - `forces_lanes.rs`: the pair force (JKR, damping, rolling, sliding, twisting);
//! - `limits_lanes.rs`: the rolling and sliding limits in lanes;
//! - `corrections_lanes.rs`: the pair contacts' inelastic corrections and their booking;
//! - `booking_lanes.rs`: the pairs pass's corrections booked in the lanes;
//! - `step_energy_lanes.rs`: a pair contact's tangential step energy, four at a time;
//! - `integrate_lanes.rs`: a pair contact's leap-frog step and tests;
//! - `walls.rs`: a monomer's wall contacts (limits and forces);
//! - `wall_planes.rs`: how many walls each monomer touches, four walls at a time.
//!
//! It names the lanes, the chunking and the prefetch hints below it, nothing above.

mod booking_lanes;
pub mod corrections_lanes;
pub mod forces_lanes;
pub mod integrate_lanes;
pub(crate) mod limits_lanes;
pub mod results;
mod step_energy_lanes;
pub mod wall_planes;
pub mod walls;
