//! Experiments: setups, wall motion, measurements and stop rules.

pub mod collision;
pub mod compression;
pub mod measure;
pub mod setup;

/// Simulated time after `step` steps of `dt` [s]. The one definition of time: both engines
/// keep their clock with it, and every output that states a time (`time_s` in curve.csv and
/// profiles.csv, snapshots and their `.pvd` series, the run summary) takes it from here, so
/// the backends and a resumed run agree to the bit however their steps were batched.
pub fn simulated_time(step: u64, dt: f64) -> f64 {
    step as f64 * dt
}
