// requires: bindings positions owner interaction rolling sliding twisting math
//
// Monomer–monomer force pass, twin of forces in src/backend/cpu/passes/forces.rs: inelastic corrections
// first (booked per channel as the drop of the contact's step energy), then JKR, damping,
// rolling, sliding and twisting.
//
// WGSL has no f64 atomics, so the pass does not add into the monomers' accumulators. Each
// invocation evaluates one contact where its history lives, stores the result per slot and
// registers the slot with the partner (`incoming`); the walls pass then gathers per monomer in
// the CPU's order (incoming by owner index, then the monomer's own slots), deterministic and
// bit-identical to the CPU sums.
//
// The corrections are rare and expensive (each books two step energies, i.e. two more contact
// evaluations), and lavapipe runs every branch for every invocation. So `contacts_scan` lists
// the owners with a contact beyond a limit (`beyond_limits` in engine/interaction.wgsl), the
// contacts pass applies the limits for just those owners after their events (dispatched
// indirectly over the list), and `forces` evaluates the contacts. The order within one
// contact (corrections, then forces) and the order of the tally additions (slot by slot, per
// channel) are the CPU's, so the results are the same bits.

// apply_inelastic_limits (engine/owner.wgsl) for the owners `contacts_scan` listed with
// OWNER_CORRECTIONS, without their contact events: the step runs both in the contacts pass
// (contacts.wgsl); this entry point lets the forces be tested on a state whose events have
// not run. Each invocation takes every stride-th entry, as the dispatch holds at most
// work_groups_max groups.
@compute @workgroup_size(WORK_GROUP)
fn forces_corrections(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * WORK_GROUP;
    let length = work_length(WORK_CONTACTS);
    for (var k = id.x; k < length; k += stride) {
        let item = work_item(WORK_CONTACTS, k);
        if (item & OWNER_CORRECTIONS) != 0u {
            apply_inelastic_limits(item & OWNER_INDEX);
        }
    }
}

// JKR, damping, rolling, sliding and twisting of every pair contact, after the corrections: one
// invocation per contact (the list contacts_scan built for this step's events; each
// invocation takes every stride-th entry, as a dispatch holds at most work_groups_max groups).
@compute @workgroup_size(PAIR_GROUP)
fn forces(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * PAIR_GROUP;
    let length = work_length(WORK_PAIRS);
    for (var k = id.x; k < length; k += stride) {
        let idx = contact_list[k];
        if pair_slot_in_use(idx) {
            contact_forces(idx);
        }
    }
}

// The forces of the pair contact in slot `idx`, stored with the slot and registered with the
// partner.
fn contact_forces(idx: u32) {
    let i = idx / params.pair_slots;
    let j = pair_partner[idx];
    let stored_n1 = load_pair_n1(idx);
    let n2 = load_pair_n2(idx).n;
    let centres = pair_centres(i, j);
    let it = pair_interaction(
        centres, velocity[i].xyz, velocity[j].xyz,
        stored_n1.n, n2, stored_n1.twist,
    );
    store_pair_result(idx, PairResult(it.f, it.fd, it.m1, it.m2));
    let at = atomicAdd(&incoming_count[j], 1u);
    if at < INCOMING_CAPACITY {
        incoming[j * INCOMING_CAPACITY + at] = idx;
    } else {
        flag(FLAG_INCOMING, j);
    }
}
