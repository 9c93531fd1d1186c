//! The step script both engines run: every pass by the name of its WGSL entry point
//! ([`Kernel`], generated from shaders/passes/ by build.rs), the order of one step
//! ([`STEP`]) and of the start ([`START`]), and the codes the passes hand each other.
//!
//! The GPU engine dispatches each pass as its entry point; the CPU engine calls the function of
//! the same name in `backend::cpu` (its executor matches on every [`Kernel`], so an entry point
//! added to the WGSL does not compile until it has a CPU twin). A pass does the same job on
//! both sides from the same inputs; where a side keeps a structure in another form (the CPU's
//! candidate pairs as one sorted list, the device's per monomer), DESIGN.md ("One step script")
//! says which and why.

include!(concat!(env!("OUT_DIR"), "/kernels.rs"));

/// The passes of one step, in order. `contacts_scan` lists the owners with contact events, a
/// contact beyond an inelastic limit or wall contacts, and `contacts` does their work;
/// `wall_forces` gathers each monomer's forces and sums the wall forces per block, which
/// `reduce_walls_final` adds up.
pub const STEP: [Kernel; 10] = [
    Kernel::IntegrateKick,
    Kernel::IntegratePairs,
    Kernel::IntegrateDrift,
    Kernel::Neighbours,
    Kernel::NeighboursList,
    Kernel::ContactsScan,
    Kernel::Contacts,
    Kernel::Forces,
    Kernel::WallForces,
    Kernel::ReduceWallsFinal,
];

/// The passes that make an engine from positions and synchronised velocities: the contacts
/// present at time 0 (not a dissipation: their tally is cleared), the forces at time 0 (no
/// step before it: the work channels are cleared), then the half-step shift of the velocities
/// the leap-frog stores.
pub const START: [Kernel; 10] = [
    Kernel::Neighbours,
    Kernel::NeighboursList,
    Kernel::ContactsScan,
    Kernel::Contacts,
    Kernel::ContactsClearTally,
    Kernel::Forces,
    Kernel::WallForces,
    Kernel::ReduceWallsFinal,
    Kernel::IntegrateClearWork,
    Kernel::IntegrateStart,
];

/// `contacts_scan`'s work item: the owner's index with what the contacts pass does for it.
pub const OWNER_EVENTS: u32 = 0x8000_0000;
pub const OWNER_CORRECTIONS: u32 = 0x4000_0000;
pub const OWNER_WALLS: u32 = 0x2000_0000;
pub const OWNER_INDEX: u32 = 0x1fff_ffff;

/// An owner's pair-contact tests (`integrate_pairs`, `contacts_pair_tests`): one of its
/// contacts breaks, one is beyond an inelastic limit.
pub const PAIR_TEST_BREAKS: u32 = 1;
pub const PAIR_TEST_BEYOND: u32 = 2;
