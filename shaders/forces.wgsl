// requires: bindings interaction rolling sliding twisting math
//
// Monomer–monomer force pass, twin of pair_forces in src/cpu/forces.rs: inelastic corrections
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
// the owners with a contact beyond a limit (`beyond_limits` in contacts.wgsl),
// `forces_corrections` applies the limits for just those owners (dispatched indirectly over the
// list), and `forces` evaluates the contacts. The
// order within one contact (corrections, then forces) and the order of the tally additions
// (slot by slot, per channel) are the CPU's, so the results are the same bits.

// apply_inelastic_limits for the contacts of the owners `contacts_scan` listed: rolling,
// sliding, twisting, each booked per channel as the drop of the contact's step energy.
// Each invocation takes every stride-th entry, as the dispatch holds at most work_groups_max
// groups.
@compute @workgroup_size(WORK_GROUP)
fn forces_corrections(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * WORK_GROUP;
    let length = work_length(WORK_CORRECTIONS);
    for (var k = id.x; k < length; k += stride) {
        apply_inelastic_limits(work_item(WORK_CORRECTIONS, k));
    }
}

// The corrections of owner `i`'s contacts.
fn apply_inelastic_limits(i: u32) {
    let k = params.pair;
    let r = params.radius;
    let x1 = position[i].xyz;
    for (var slot = 0u; slot < pair_count[i]; slot++) {
        let idx = i * params.pair_slots + slot;
        let j = pair_partner[idx];
        let x2 = position[j].xyz;
        let stored_n1 = load_pair_n1(idx);
        var n1 = stored_n1.xyz;
        var n2 = load_pair_n2(idx).xyz;
        var twist = stored_n1.w;

        let nc = vec_normalize(x1 - x2);
        let rolled = rolling_correction(n1, n2, k.reduced_radius, k.xi_crit);
        if rolled.changed {
            let before = pair_step_energy(i, j, n1, n2, twist);
            n1 = rolled.n1;
            n2 = rolled.n2;
            add_tally(i, TALLY_ROLLING, before - pair_step_energy(i, j, n1, n2, twist));
        }
        let slid = sliding_correction(n1, n2, nc, r, r, k.zeta_crit);
        if slid.changed {
            let before = pair_step_energy(i, j, n1, n2, twist);
            n1 = slid.n1;
            n2 = slid.n2;
            add_tally(i, TALLY_SLIDING, before - pair_step_energy(i, j, n1, n2, twist));
        }
        let twisted = twisting_correction(twist, k.phi_crit);
        if twisted.changed {
            let before = pair_step_energy(i, j, n1, n2, twist);
            twist = twisted.twist;
            add_tally(i, TALLY_TWISTING, before - pair_step_energy(i, j, n1, n2, twist));
        }
        store_pair_n1(idx, vec4<f64>(n1, twist));
        store_pair_n2(idx, vec4<f64>(n2, 0.0lf));
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
    let n2 = load_pair_n2(idx).xyz;
    let it = pair_interaction(
        position[i].xyz, position[j].xyz, velocity[i].xyz, velocity[j].xyz,
        stored_n1.xyz, n2, stored_n1.w,
    );
    store_pair_result(idx, PairResult(it.f, it.fd, it.m1, it.m2));
    let at = atomicAdd(&incoming_count[j], 1u);
    if at < INCOMING_CAPACITY {
        incoming[j * INCOMING_CAPACITY + at] = idx;
    } else {
        flag(FLAG_INCOMING, j);
    }
}
