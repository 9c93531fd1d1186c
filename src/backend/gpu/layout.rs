//! Host encodings of values the WGSL modules take as structs. Keep in sync with the WGSL
//! declarations named on each item; the tests in `twins` tie the numbers together.

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
}

const _: () = assert!(std::mem::size_of::<GpuParams>() == 208);

/// The WGSL `Wall` struct of shaders/engine/bindings.wgsl (vectors as vec4, w unused).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuWall {
    pub point: [f64; 4],
    pub normal: [f64; 4],
    pub velocity: [f64; 4],
    pub k: GpuConstants,
}

const _: () = assert!(std::mem::size_of::<GpuWall>() == 192);

/// The block sizes of the fixed summation order both backends follow (`state::reduction`),
/// which bindings.wgsl declares too.
pub use crate::state::reduction::{DIAG_THREADS, REDUCE_BLOCK, TALLY_STRIDE};
/// Numbers shared with shaders/engine/bindings.wgsl; `tests` checks them against the WGSL.
pub const MAX_WALLS: usize = 8;
pub const INCOMING_CAPACITY: usize = 16;
pub const NEIGHBOUR_CAPACITY: usize = 24;
pub const SLOT_CHUNKS: usize = 3;
/// Work lists (bindings.wgsl `work_list`, lengths in `work`, indirect dispatch arguments in
/// `work_args`, three words per list), and the workgroup size of the passes dispatched over a
/// list.
/// The owners with contact events, inelastic corrections or wall contacts (the contacts pass).
pub const WORK_CONTACTS: usize = 0;
/// The pair-contact list (`contact_list`), for the passes run one invocation per contact.
pub const WORK_PAIRS: usize = 1;
pub const WORK_LISTS: usize = 2;
/// Indirect dispatch arguments of the neighbour passes, after the lists' in `work_args`.
pub const ARGS_REBUILD: usize = 2;
/// The lists in `work_list` (filled by contacts_scan, emptied by integrate_drift).
pub const EVENT_LISTS: usize = 1;
pub const WORK_GROUP: usize = 8;
/// Workgroup size of the passes over the pair-contact list.
pub const PAIR_GROUP: usize = 64;
/// Workgroup size of the passes with one invocation per monomer.
pub const MONOMER_GROUP: usize = 64;
pub const DIAG_PAIR_CONTACTS: usize = 8;
pub const DIAG_WALL_CONTACTS: usize = 9;
pub const DIAG_STEPS: usize = 10;
pub const DIAG_WALL_FORCE: usize = 16;
pub const DIAG_WALL_FORCE_SUM: usize = 48;
pub const DIAG_SIZE: usize = 80;
/// Where the row kernels (shaders/passes/rows.wgsl) find their parameters and leave their
/// results in `row_data`.
pub const ROW_MASS: usize = 0;
pub const ROW_INERTIA: usize = 1;
pub const ROW_SPHERE: usize = 2;
pub const ROW_SLAB_BOTTOM: usize = 3;
pub const ROW_SLAB_THICKNESS: usize = 4;
pub const ROW_SLABS: usize = 5;
pub const ROW_X0: usize = 6;
pub const ROW_Y0: usize = 7;
pub const ROW_PIXEL: usize = 8;
pub const ROW_NX: usize = 9;
pub const ROW_NY: usize = 10;
pub const ROW_RESULTS: usize = 16;
pub use crate::state::rows::ROW_SUMS;
pub const ROW_PARTIALS: usize = 24;
/// Flags: index into the flags array, and what overflowed.
pub const FLAG_PAIR_SLOTS: usize = 0;
pub const FLAG_WALL_SLOTS: usize = 1;
pub const FLAG_BUCKET: usize = 2;
pub const FLAG_INCOMING: usize = 3;
pub const FLAG_NON_FINITE: usize = 4;
pub const FLAG_NEIGHBOURS: usize = 5;
pub const FLAG_REBUILD: usize = 6;
pub const FLAG_COUNT: usize = 8;
pub const NO_MONOMER: u32 = u32::MAX;

pub fn vec4(v: glam::DVec3) -> [f64; 4] {
    [v.x, v.y, v.z, 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::gpu::shader::{assemble, modules, ENGINE};

    fn engine_module() -> naga::Module {
        let bindings = ENGINE.iter().find(|m| m.name() == "bindings").unwrap();
        assemble(bindings, &modules())
            .unwrap()
            .validate()
            .unwrap()
            .0
    }

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
                pair
            )
        );
        let w = wgsl_struct(&module, "Wall");
        assert_eq!(w.0 as usize, std::mem::size_of::<GpuWall>());
        assert_eq!(w.1, offsets!(GpuWall, point, normal, velocity, k));
    }

    #[test]
    fn shared_numbers_match_the_wgsl_constants() {
        let module = engine_module();
        let constant = |name: &str| -> u64 {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no const {name}"));
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => u64::from(v),
                ref other => panic!("{name}: {other:?}"),
            }
        };
        for (name, value) in [
            ("MAX_WALLS", MAX_WALLS),
            ("INCOMING_CAPACITY", INCOMING_CAPACITY),
            ("REDUCE_BLOCK", REDUCE_BLOCK),
            ("DIAG_THREADS", DIAG_THREADS),
            ("TALLY_STRIDE", TALLY_STRIDE),
            ("DIAG_PAIR_CONTACTS", DIAG_PAIR_CONTACTS),
            ("DIAG_WALL_CONTACTS", DIAG_WALL_CONTACTS),
            ("DIAG_STEPS", DIAG_STEPS),
            ("DIAG_WALL_FORCE", DIAG_WALL_FORCE),
            ("DIAG_WALL_FORCE_SUM", DIAG_WALL_FORCE_SUM),
            ("DIAG_SIZE", DIAG_SIZE),
            ("ROW_MASS", ROW_MASS),
            ("ROW_INERTIA", ROW_INERTIA),
            ("ROW_SPHERE", ROW_SPHERE),
            ("ROW_SLAB_BOTTOM", ROW_SLAB_BOTTOM),
            ("ROW_SLAB_THICKNESS", ROW_SLAB_THICKNESS),
            ("ROW_SLABS", ROW_SLABS),
            ("ROW_X0", ROW_X0),
            ("ROW_Y0", ROW_Y0),
            ("ROW_PIXEL", ROW_PIXEL),
            ("ROW_NX", ROW_NX),
            ("ROW_NY", ROW_NY),
            ("ROW_RESULTS", ROW_RESULTS),
            ("ROW_SUMS", ROW_SUMS),
            ("ROW_PARTIALS", ROW_PARTIALS),
            ("FLAG_PAIR_SLOTS", FLAG_PAIR_SLOTS),
            ("FLAG_WALL_SLOTS", FLAG_WALL_SLOTS),
            ("FLAG_BUCKET", FLAG_BUCKET),
            ("FLAG_INCOMING", FLAG_INCOMING),
            ("FLAG_NON_FINITE", FLAG_NON_FINITE),
            ("FLAG_NEIGHBOURS", FLAG_NEIGHBOURS),
            ("FLAG_REBUILD", FLAG_REBUILD),
            ("NEIGHBOUR_CAPACITY", NEIGHBOUR_CAPACITY),
            ("SLOT_CHUNKS", SLOT_CHUNKS),
            ("WORK_CONTACTS", WORK_CONTACTS),
            ("WORK_PAIRS", WORK_PAIRS),
            ("WORK_LISTS", WORK_LISTS),
            ("ARGS_REBUILD", ARGS_REBUILD),
            ("EVENT_LISTS", EVENT_LISTS),
            ("WORK_GROUP", WORK_GROUP),
            ("PAIR_GROUP", PAIR_GROUP),
            ("MONOMER_GROUP", MONOMER_GROUP),
            ("NO_MONOMER", NO_MONOMER as usize),
        ] {
            assert_eq!(constant(name), value as u64, "{name}");
        }
    }
}
