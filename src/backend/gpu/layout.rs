//! Host encodings of values the WGSL modules take as structs (their layouts are held to naga's
//! reading of the WGSL by the tests below), and the numbers the WGSL declares, generated.

use super::shader::Precision;
use crate::material::ContactConstants;
use crate::model::Damping;
use bytemuck::{Pod, Zeroable};

/// `DAMPING_NONE` etc. of shaders/model/damping.wgsl.
pub const DAMPING_NONE: u32 = 0;
pub const DAMPING_VISCOUS: u32 = 1;
pub const DAMPING_VISCOELASTIC: u32 = 2;

/// The WGSL `Damping` struct of shaders/model/damping.wgsl: a tag and its one parameter.
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

/// The WGSL `Constants` struct of shaders/engine/bindings.wgsl: `material::ContactConstants`
/// in field order, padded to 96 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuConstants {
    pub reduced_radius: f64,
    pub a0: f64,
    pub delta0: f64,
    pub f_c: f64,
    pub delta_c: f64,
    pub k_r: f64,
    pub k_s: f64,
    pub k_t: f64,
    pub xi_crit: f64,
    pub zeta_crit: f64,
    pub phi_crit: f64,
    pub _pad: f64,
}

const _: () = assert!(std::mem::size_of::<GpuConstants>() == 96);

impl From<ContactConstants> for GpuConstants {
    fn from(c: ContactConstants) -> Self {
        GpuConstants {
            reduced_radius: c.reduced_radius,
            a0: c.a0,
            delta0: c.delta0,
            f_c: c.f_c,
            delta_c: c.delta_c,
            k_r: c.k_r,
            k_s: c.k_s,
            k_t: c.k_t,
            xi_crit: c.xi_crit,
            zeta_crit: c.zeta_crit,
            phi_crit: c.phi_crit,
            _pad: 0.0,
        }
    }
}

/// The WGSL `Params` struct of shaders/engine/bindings.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuParams {
    pub n: u32,
    pub wall_count: u32,
    pub pair_slots: u32,
    pub wall_slots: u32,
    pub table_mask: u32,
    pub bucket_capacity: u32,
    pub damping_kind: u32,
    /// Elements in each binding of a per-slot vector array.
    pub slot_chunk: u32,
    /// Most workgroups a pass over a work list is dispatched with (the device's limit per
    /// dimension); longer lists are walked with a stride.
    pub work_groups_max: u32,
    pub _pad: u32,
    pub _pad2: u32,
    pub _pad3: u32,
    pub dt: f64,
    pub radius: f64,
    pub inverse_mass: f64,
    pub inverse_inertia: f64,
    pub cell: f64,
    pub e_star: f64,
    pub poisson: f64,
    pub damping_value: f64,
    pub pair: GpuConstants,
    /// The mixed precision's low parts of the radius and (2r)², and (2r)² (zero in the exact
    /// precision: unread there).
    pub radius_lo: f64,
    pub two_r_squared: f64,
    pub two_r_squared_lo: f64,
}

const _: () = assert!(std::mem::size_of::<GpuParams>() == 232);

impl GpuParams {
    /// In the mixed precision, the radius's and (2r)²'s double-f32 parts: each f32 and what it
    /// leaves out (the host's f64 arithmetic; 4r² is exact in f64 to 2⁻⁵³).
    pub fn with_split_radius(mut self, precision: Precision) -> Self {
        if precision == Precision::Mixed {
            let r = self.radius;
            self.radius_lo = r - f64::from(r as f32);
            let square = 4.0 * r * r;
            self.two_r_squared = square;
            self.two_r_squared_lo = square - f64::from(square as f32);
        }
        self
    }
}

/// The WGSL `Wall` struct of shaders/engine/bindings.wgsl (vectors as vec4, w unused).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuWall {
    pub point: [f64; 4],
    pub normal: [f64; 4],
    pub velocity: [f64; 4],
    pub k: GpuConstants,
    /// The mixed precision's low part of `point` (zero in the exact precision).
    pub point_lo: [f64; 4],
}

const _: () = assert!(std::mem::size_of::<GpuWall>() == 224);

/// The WGSL `MonomerAux` struct of shaders/engine/bindings.wgsl: a monomer's mobility scales
/// and the power of its wall contacts at the current step.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuMonomerAux {
    pub inverse_mass_scale: f64,
    pub inverse_inertia_scale: f64,
    pub wall_power: f64,
    pub damping_power: f64,
}

/// The numbers the WGSL declares (work lists, flags, the diagnostics and row blocks), generated
/// from shaders/engine/bindings.wgsl at build time (`backend::gpu::interface`).
pub use super::interface::wgsl_constants::*;
/// The block sizes of the fixed summation order both backends follow (`state::reduction`) and
/// the row sums: the CPU engine owns these numbers; bindings.wgsl declares them too, and
/// `tests` holds the two equal.
pub use crate::state::reduction::{DIAG_THREADS, REDUCE_BLOCK, TALLY_STRIDE};
pub use crate::state::rows::ROW_SUMS;
/// No monomer (a flag not raised), as the u32 the flags hold.
pub const NO_MONOMER: u32 = super::interface::wgsl_constants::NO_MONOMER as u32;

pub fn vec4(v: glam::DVec3) -> [f64; 4] {
    [v.x, v.y, v.z, 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::gpu::shader::engine_module;

    /// (size, [(member, offset)]) of the WGSL struct `name`.
    fn wgsl_struct(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"));
        match &ty.inner {
            naga::TypeInner::Struct { members, span } => (
                *span,
                members
                    .iter()
                    .map(|m| (m.name.clone().unwrap(), m.offset))
                    .collect(),
            ),
            other => panic!("{name} is {other:?}"),
        }
    }

    macro_rules! offsets {
        ($t:ty, $($f:ident),*) => {
            vec![$((stringify!($f).to_string(), std::mem::offset_of!($t, $f) as u32)),*]
        };
    }

    #[test]
    fn rust_structs_match_the_wgsl_layout() {
        let module = engine_module();
        let c = wgsl_struct(&module, "Constants");
        assert_eq!(c.0 as usize, std::mem::size_of::<GpuConstants>());
        assert_eq!(
            c.1,
            offsets!(
                GpuConstants,
                reduced_radius,
                a0,
                delta0,
                f_c,
                delta_c,
                k_r,
                k_s,
                k_t,
                xi_crit,
                zeta_crit,
                phi_crit,
                _pad
            )
        );
        let p = wgsl_struct(&module, "Params");
        assert_eq!(p.0 as usize, std::mem::size_of::<GpuParams>());
        assert_eq!(
            p.1,
            offsets!(
                GpuParams,
                n,
                wall_count,
                pair_slots,
                wall_slots,
                table_mask,
                bucket_capacity,
                damping_kind,
                slot_chunk,
                work_groups_max,
                _pad,
                _pad2,
                _pad3,
                dt,
                radius,
                inverse_mass,
                inverse_inertia,
                cell,
                e_star,
                poisson,
                damping_value,
                pair,
                radius_lo,
                two_r_squared,
                two_r_squared_lo
            )
        );
        let a = wgsl_struct(&module, "MonomerAux");
        assert_eq!(a.0 as usize, std::mem::size_of::<GpuMonomerAux>());
        assert_eq!(
            a.1,
            offsets!(
                GpuMonomerAux,
                inverse_mass_scale,
                inverse_inertia_scale,
                wall_power,
                damping_power
            )
        );
        // The host writes a pointer and its twist as [x, y, z, twist] (engine::upload).
        let pointer = wgsl_struct(&module, "ContactPointer");
        assert_eq!(pointer, (32, vec![("n".into(), 0), ("twist".into(), 24)]));
        let w = wgsl_struct(&module, "Wall");
        assert_eq!(w.0 as usize, std::mem::size_of::<GpuWall>());
        assert_eq!(w.1, offsets!(GpuWall, point, normal, velocity, k, point_lo));
    }

    #[test]
    fn numbers_the_cpu_engine_owns_match_the_wgsl() {
        use super::super::interface::wgsl_constants as wgsl;
        assert_eq!(wgsl::DIAG_THREADS, DIAG_THREADS);
        assert_eq!(wgsl::REDUCE_BLOCK, REDUCE_BLOCK);
        assert_eq!(wgsl::TALLY_STRIDE, TALLY_STRIDE);
        assert_eq!(wgsl::ROW_SUMS, ROW_SUMS);
        assert_eq!(NO_MONOMER, u32::MAX);
    }
}
