//! dustdem: molecular dynamics of porous dust agglomerates.

// The CPU passes mirror GPU kernels: index loops over monomers and explicit argument lists are
// their structure, kept on purpose so each pass reads like its WGSL twin.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

pub mod analysis;
pub mod backend;
pub mod bench;
pub mod binary;
pub mod calibrate;
pub mod cli;
pub mod config;
pub mod engine;
pub mod experiment;
pub mod job;
pub mod material;
pub mod mixed;
pub mod model;
pub mod output;
pub mod reproduce;
pub mod rng;
pub mod sample;
pub mod state;
pub mod sweep;

/// Exit status of `run`, `resume` and `sweep` when a signal stopped them after a checkpoint
/// (BSD's EX_TEMPFAIL: try again later). A job script requeues on it; `dustdem resume` or the
/// same sweep command continues.
pub const RESUMABLE_EXIT: u8 = 75;
