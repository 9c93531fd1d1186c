//! What can stop the GPU engine, and how it becomes the engine contract's error.

use crate::backend::gpu::buffers::SizeError;
use crate::backend::gpu::context::ContextError;
use crate::backend::gpu::shader::ShaderError;
use crate::engine::EngineError;
use std::fmt;

/// Everything that can stop the GPU engine.
#[derive(Debug)]
pub enum GpuError {
    Context(ContextError),
    Shader(ShaderError),
    Size(SizeError),
    /// Slot overflow or a non-finite state, as the CPU engine reports them.
    Engine(EngineError),
    /// More monomers hashed to one bucket of the cell table than it holds.
    BucketOverflow {
        monomer: usize,
        capacity: usize,
    },
    /// More candidate partners within 2r + skin than a candidate list holds.
    NeighbourOverflow {
        monomer: usize,
        capacity: usize,
    },
    /// The device was lost or reported an error: nothing on it can be trusted or read.
    DeviceLost(String),
    /// More contacts with owners of lower index than the gather list holds.
    IncomingOverflow {
        monomer: usize,
        capacity: usize,
    },
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GpuError::Context(e) => write!(f, "{e}"),
            GpuError::Shader(e) => write!(f, "{e}"),
            GpuError::Size(e) => write!(f, "{e}"),
            GpuError::Engine(e) => write!(f, "{e}"),
            GpuError::BucketOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} found its cell of the GPU's cell table full ({capacity} \
                 monomers); {OVERLAP_ADVICE}"
            ),
            GpuError::NeighbourOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} has more than {capacity} candidate partners within 2r + skin \
                 on the GPU; {OVERLAP_ADVICE}"
            ),
            GpuError::DeviceLost(why) => write!(f, "the GPU failed: {why}"),
            GpuError::IncomingOverflow { monomer, capacity } => write!(
                f,
                "monomer {monomer} has more than {capacity} contacts with lower-index monomers \
                 on the GPU; {OVERLAP_ADVICE}"
            ),
        }
    }
}

/// What the fixed per-monomer lists of the GPU engine that have no config key (cell-table
/// buckets, candidate lists, incoming contacts) overflowing means, and what to change. Each
/// holds more than equal spheres that do not overlap can ever need (at most 12 touch one), so
/// only a state that has gone wrong fills one.
const OVERLAP_ADVICE: &str = "monomers overlap far beyond contact, more than equal spheres \
     ever need: lower [integration] dt_ns to within the stability limit (`dustdem info` prints \
     it) or [experiment] wall_speed_m_s, or remove overlapping monomers from the [sample] file";

impl std::error::Error for GpuError {}

impl From<ContextError> for GpuError {
    fn from(e: ContextError) -> Self {
        GpuError::Context(e)
    }
}
impl From<ShaderError> for GpuError {
    fn from(e: ShaderError) -> Self {
        GpuError::Shader(e)
    }
}
impl From<SizeError> for GpuError {
    fn from(e: SizeError) -> Self {
        GpuError::Size(e)
    }
}
impl From<EngineError> for GpuError {
    fn from(e: EngineError) -> Self {
        GpuError::Engine(e)
    }
}

/// The engine contract's error: a guard the device raised is the engine's own, a lost device
/// is `DeviceLost`, everything else the GPU's error as it is.
impl From<GpuError> for EngineError {
    fn from(e: GpuError) -> Self {
        match e {
            GpuError::Engine(e) => e,
            GpuError::DeviceLost(why) => EngineError::DeviceLost(why),
            other => EngineError::Backend(Box::new(other)),
        }
    }
}
