//! Host encodings of values the WGSL modules take as structs. Keep in sync with the WGSL
//! declarations named on each item; the tests in `twins` tie the numbers together.

use crate::model::Damping;
use bytemuck::{Pod, Zeroable};

/// `DAMPING_NONE` etc. of shaders/shared/damping.wgsl.
pub const DAMPING_NONE: u32 = 0;
pub const DAMPING_VISCOUS: u32 = 1;
pub const DAMPING_VISCOELASTIC: u32 = 2;

/// The WGSL `Damping` struct of shaders/shared/damping.wgsl: a tag and its one parameter.
/// WGSL aligns the f64 to 8 bytes, hence the explicit padding.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuDamping {
    pub kind: u32,
    pub _pad: u32,
    /// κ [g/s] for viscous, T_vis [s] for viscoelastic damping, 0 for none.
    pub value: f64,
}

const _: () = assert!(std::mem::size_of::<GpuDamping>() == 16);

impl From<Damping> for GpuDamping {
    fn from(d: Damping) -> Self {
        let (kind, value) = match d {
            Damping::None => (DAMPING_NONE, 0.0),
            Damping::Viscous { kappa } => (DAMPING_VISCOUS, kappa),
            Damping::Viscoelastic { t_vis } => (DAMPING_VISCOELASTIC, t_vis),
        };
        GpuDamping {
            kind,
            _pad: 0,
            value,
        }
    }
}
