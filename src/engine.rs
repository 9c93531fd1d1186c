//! The contract between the experiments and the backends: the [`Engine`] trait every backend
//! implements, the one error type it reports ([`EngineError`]), and the numerical conventions
//! every backend keeps so that they step the same state to the same bits.
//!
//! Experiments are written against this trait alone; which backend runs is chosen in `job`.

use crate::model::ContactLaw;
use crate::state::rows::{RowMeasures, RowRequest};
use crate::state::{simulated_time, EnergyReport, State, Wall};
use glam::DVec3;
use std::borrow::Cow;
use std::fmt;

/// Skin of the candidate lists (CPU neighbour list and device candidate lists) in monomer radii:
/// a list stays valid until some monomer has moved half of it, ~200 steps at 1 m/s and
/// dt = 0.3 ns.
pub const SKIN_RADII: f64 = 0.2;

/// Why an engine stopped.
#[derive(Debug)]
pub enum EngineError {
    /// A monomer needs more contact slots than the state has (a run-time guard).
    SlotOverflow {
        kind: &'static str,
        step: u64,
        monomer: usize,
        limit: usize,
    },
    /// A position or velocity is no longer finite (a run-time guard).
    NonFinite { step: u64, monomer: usize },
    /// Two monomers (or a monomer and a wall) overlap by more than half a radius: the time
    /// step is far too large or the state is corrupt (a run-time guard).
    RunawayOverlap {
        step: u64,
        monomer: usize,
        partner: String,
        overlap: f64,
    },
    /// The device failed: nothing of the state on it can be read.
    DeviceLost(String),
    /// Any other failure of a backend (its setup, its memory, its own fixed-size lists), as
    /// the backend reports it.
    Backend(Box<dyn std::error::Error + Send + Sync>),
}

impl EngineError {
    /// The error with the step it happened at, where it names one that its pass did not know.
    pub fn at_step(self, at: u64) -> Self {
        match self {
            EngineError::SlotOverflow {
                kind,
                monomer,
                limit,
                ..
            } => EngineError::SlotOverflow {
                kind,
                step: at,
                monomer,
                limit,
            },
            other => other,
        }
    }

    /// A run-time guard fired: the state can still be read, and shows what went wrong.
    pub fn is_guard(&self) -> bool {
        matches!(
            self,
            EngineError::SlotOverflow { .. }
                | EngineError::NonFinite { .. }
                | EngineError::RunawayOverlap { .. }
        )
    }
}

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EngineError::SlotOverflow {
                kind,
                step,
                monomer,
                limit,
            } => write!(
                f,
                "at step {step}, monomer {monomer} needs more than {limit} {kind} contact slots; raise \
                 [integration] {} in the config",
                if *kind == "monomer-wall" {
                    "wall_slots"
                } else {
                    "pair_slots"
                }
            ),
            EngineError::NonFinite { step, monomer } => write!(
                f,
                "non-finite position or velocity of monomer {monomer} at step {step} \
                 (time step too large or overlapping monomers?)"
            ),
            EngineError::RunawayOverlap {
                step,
                monomer,
                partner,
                overlap,
            } => write!(
                f,
                "runaway overlap at step {step}: monomer {monomer} and {partner} overlap by \
                 {overlap:.3e} cm, more than half a radius (time step too large?)"
            ),
            EngineError::DeviceLost(why) => write!(f, "the device failed: {why}"),
            EngineError::Backend(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for EngineError {}

/// What an experiment needs of a backend. Everything a measurement reports goes through it, so
/// every backend writes the same rows.
pub trait Engine {
    fn law(&self) -> &ContactLaw;
    /// Walls at the current time.
    fn walls(&self) -> &[Wall];
    fn monomer_count(&self) -> usize;
    fn step_count(&self) -> u64;
    /// The time step [s].
    fn dt(&self) -> f64;
    /// Simulated time [s]: [`simulated_time`] of the step count; not overridden.
    fn time(&self) -> f64 {
        simulated_time(self.step_count(), self.dt())
    }
    /// Advances `steps` steps.
    fn advance(&mut self, steps: u64) -> Result<(), EngineError>;
    /// Advances `steps` steps and returns each wall's force on the monomers averaged over them.
    fn run_mean_wall_force(&mut self, steps: u64) -> Result<Vec<DVec3>, EngineError>;
    fn positions(&self) -> Cow<'_, [DVec3]>;
    /// (monomer–monomer contacts, monomer–wall contacts).
    fn contact_counts(&self) -> (usize, usize);
    fn energy(&self) -> EnergyReport;
    /// What a measurement row reads of the state: energies and contact counts, and as
    /// requested the solid volume per slab and the projected area, reduced in the fixed order
    /// of `state::rows`. A device reduces them on its side and reads back a few numbers (the
    /// full state would be gigabytes per row at 10⁶ monomers); by default they come from
    /// [`Engine::state`], which the CPU engine holds. `&mut`: a device may grow its scratch
    /// buffers for a larger profile or raster.
    fn row_measures(&mut self, request: &RowRequest) -> Result<RowMeasures, EngineError> {
        Ok(self.state().row_measures(request))
    }
    /// The complete state (borrowed where the engine holds it, read back from a device): for
    /// checkpoints, snapshots and failure reports.
    fn state(&self) -> Cow<'_, State>;

    /// Stops booking the inelastic corrections' dissipation: those channels of the tally
    /// become NaN ([`crate::state::Dissipation::without_corrections`]), and the engine may skip
    /// the step energies they need. The trajectory is unchanged.
    fn stop_tallying_corrections(&mut self);

    /// Bytes of host memory the engine's arrays hold, where it keeps its state there (the CPU
    /// engine); `None` for an engine whose state lives on a device.
    fn host_bytes(&self) -> Option<u64> {
        None
    }
}
