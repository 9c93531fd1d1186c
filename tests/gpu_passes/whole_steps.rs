//! Whole steps run another way (profiled, per-slot arrays split over three bindings, work
//! lists walked with a stride) give the same bits as plain steps.

use crate::support::{crafted, gpu_laid_out, gpu_of};
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::state::ContactTable;

#[test]
fn profiled_steps_are_ordinary_steps() {
    let state = crafted().cpu;
    let (Some(mut profiled), Some(mut plain)) = (gpu_of(&state), gpu_of(&state)) else {
        return;
    };
    let Some(times) = profiled.profile_passes(5).unwrap() else {
        eprintln!("notice: no timestamp queries inside passes on this device");
        return;
    };
    plain.run(5).unwrap();
    assert_eq!(times.len(), GpuEngine::passes().len());
    assert!(times.iter().all(|(_, s)| *s > 0.0), "{times:?}");
    assert_eq!(profiled.step, plain.step);
    assert_eq!(profiled.positions(), plain.positions());
    assert_eq!(profiled.diagnostics(), plain.diagnostics());
}

#[test]
fn per_slot_arrays_in_one_binding_or_split_over_three_give_the_same_bits() {
    // Large N (above 349 525 with 12 slots) split every per-slot array over three bindings;
    // smaller N keep them in one, and the tests above hold that layout to the CPU. Both
    // layouts, run 50 steps from the crafted aggregate, must agree to the bit.
    let state = crafted().cpu;
    let (Some(mut one), Some(mut split)) =
        (gpu_laid_out(&state, false), gpu_laid_out(&state, true))
    else {
        return;
    };
    assert!(one.sizes.one_slot_chunk() && !split.sizes.one_slot_chunk());
    one.run(50).unwrap();
    split.run(50).unwrap();
    assert_eq!(one.monomers(), split.monomers());
    assert_eq!(one.contacts(), split.contacts());
    assert!(one.contacts().pair_contact_count() > 0);
}

#[test]
fn work_lists_longer_than_one_dispatch_are_walked_with_a_stride() {
    // A pass over a work list has at most the device's workgroups per dimension (65 535 of 8
    // invocations); longer lists (N > 524 280, e.g. forming a 10⁶-monomer sample's first
    // contacts) are walked with a stride. Here the limit is one workgroup, and the crafted
    // aggregate starts with no contacts, so the first step lists every touching owner: the
    // result must equal the unlimited engine's to the bit.
    let mut state = crafted().cpu;
    let t = &state.contacts;
    state.contacts = ContactTable::new(state.monomers.len(), t.pair_slots, t.wall_slots);
    let (Some(mut plain), Some(mut limited)) = (gpu_of(&state), gpu_of(&state)) else {
        return;
    };
    limited.limit_work_groups(1);
    plain.run(20).unwrap();
    limited.run(20).unwrap();
    let formed = plain.contacts().pair_contact_count();
    eprintln!("{formed} pair contacts formed");
    assert!(formed > 100, "the first step formed many contacts");
    assert_eq!(plain.contacts(), limited.contacts());
    assert_eq!(plain.monomers(), limited.monomers());
}
