// requires: bindings positions cells owner interaction wall rolling sliding twisting math
//
// Contact maintenance pass, twin of contacts in src/backend/cpu/passes/contacts.rs: breaks stretched
// contacts (δ < −δ_c) and forms new ones (δ ≥ 0), keeping the history of every contact that
// persists. One invocation per owner: it alone writes the owner's slots, so no two invocations
// touch the same contact. Few owners have an event in a step, so a scan lists them and the
// events are processed for the listed owners only (see `work_list` in bindings.wgsl).
//
// Order as on the CPU: broken slots are replaced by the last one (swap-remove); new pair contacts
// are appended in increasing partner index (both sides' candidate lists are sorted); new wall
// contacts are appended in wall order. The energies of the events go to the owner's own tally.

fn has_wall(i: u32, count: u32, w: u32) -> bool {
    for (var slot = 0u; slot < count; slot++) {
        if wall_id[i * params.wall_slots + slot] == w {
            return true;
        }
    }
    return false;
}

// Lists the owners that have a contact event this step (a contact to break or one to form,
// tested exactly as `contacts` tests them, so an owner left out has nothing to do there), the
// owners with a contact beyond an inelastic limit, the monomers with wall contacts (one list
// for the contacts pass, with what each owner needs) and the pair contacts as the events will leave them (the
// contact-parallel passes). The number of contacts each owner can form bounds its slots after
// the events, so the pair-contact list needs no pass after the events. The lists were
// emptied by integrate_drift (or are fresh from the upload); a second scan before the next
// drift would list owners twice.
@compute @workgroup_size(MONOMER_GROUP)
fn contacts_scan(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    // Every neighbour pass of this step is done: the lists are fresh.
    if i == 0u {
        atomicStore(&flags[FLAG_REBUILD], NO_MONOMER);
        atomicStore(&work_args[3u * ARGS_REBUILD], 0u);
    }
    if i >= params.n {
        return;
    }
    let count = pair_count[i];
    // The pair contacts' tests ran per contact, in integrate_pairs (contacts_pair_tests after
    // an upload): a loop over each owner's slots here kept most SIMD lanes idle.
    let tests = atomicLoad(&pair_tests[i]);
    var event = (tests & PAIR_TEST_BREAKS) != 0u;
    let beyond = (tests & PAIR_TEST_BEYOND) != 0u;
    let wcount = wall_count[i];
    var touching_wall_contacts = 0u;
    for (var slot = 0u; slot < wcount; slot++) {
        let w = wall_id[i * params.wall_slots + slot];
        let delta = wall_overlap_at(i, wall_table[w].point.xyz, wall_table[w].point_lo.xyz, wall_table[w].normal.xyz);
        event = event || delta < -wall_table[w].k.delta_c;
        touching_wall_contacts += select(0u, 1u, !(delta < 0.0lf));
    }
    let list = i * NEIGHBOUR_CAPACITY;
    var forming = 0u;
    for (var k = 0u; k < neighbour_count[i]; k++) {
        let j = neighbour_list[list + k];
        let touching = !(pair_overlap_of(i, j) < 0.0lf);
        forming += select(0u, 1u, touching);
    }
    // A loop of constant length, which the compiler unrolls: each wall is then read at a
    // constant offset, which llvmpipe loads once per SIMD group (a uniform read at a loop
    // counter is read lane by lane).
    var touching_walls = 0u;
    for (var w = 0u; w < MAX_WALLS; w++) {
        let touching = !(wall_overlap_at(i, walls[w].point.xyz, walls[w].point_lo.xyz, walls[w].normal.xyz) < 0.0lf);
        touching_walls += select(0u, 1u, touching && w < params.wall_count);
    }
    let forms_wall_contact = touching_walls > touching_wall_contacts;
    event = event || forming > 0u || forms_wall_contact;
    // Walls: every monomer that has a wall contact after this step's events (a superset: some
    // of these contacts may break).
    let work = select(0u, OWNER_EVENTS, event) | select(0u, OWNER_CORRECTIONS, beyond)
        | select(0u, OWNER_WALLS, wcount > 0u || forms_wall_contact);
    if work != 0u {
        push_work(WORK_CONTACTS, i | work);
    }
    // The pair contacts: the slots below the count before the events plus the contacts that
    // can form (as many as fit; contact_events flags the rest), a bound on the count before
    // and after the events (breaking contacts are swapped out, new ones appended). The passes
    // over the list skip a slot at or above the owner's count, so the list also serves a state
    // whose events have not run, and an owner whose contacts both break and form lists a few
    // empty slots.
    let listed = min(count + forming, params.pair_slots);
    if listed > 0u {
        push_pairs(i, listed);
    }
    // Empty the cell table again for the next rebuild: a monomer was put in the bucket of its
    // reference position, so these stores reach every bucket that holds one (and store 0 to
    // empty ones between rebuilds).
    atomicStore(&bucket_count[bucket_of(cell_of(reference_position[i].xyz))], 0u);
}

// The events of the owners `contacts_scan` listed, then the inelastic corrections of their
// pair contacts, then their wall contacts' limits and forces (engine/owner.wgsl; the order of
// the CPU, which applies the limits at the start of the force computation). An owner's events,
// corrections and wall contacts touch only its own slots and tally, so one invocation per
// owner does all of them. Dispatched indirectly over the list; each invocation takes every
// stride-th entry, as the dispatch holds at most work_groups_max groups.
@compute @workgroup_size(WORK_GROUP)
fn contacts(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * WORK_GROUP;
    let length = work_length(WORK_CONTACTS);
    for (var k = id.x; k < length; k += stride) {
        let item = work_item(WORK_CONTACTS, k);
        let i = item & OWNER_INDEX;
        if (item & OWNER_EVENTS) != 0u {
            contact_events(i);
        }
        if (item & OWNER_CORRECTIONS) != 0u {
            apply_inelastic_limits(i);
        }
        if (item & OWNER_WALLS) != 0u {
            wall_contacts_of(i);
        }
    }
}

// Breaks and forms the contacts of owner `i`.
fn contact_events(i: u32) {
    let r = params.radius;
    let base = i * params.pair_slots;

    // Break.
    var count = pair_count[i];
    var slot = 0u;
    while slot < count {
        let idx = base + slot;
        let j = pair_partner[idx];
        let delta = pair_overlap_of(i, j);
        if delta < -params.pair.delta_c {
            let a = load_pair_n1(idx);
            add_tally(i, TALLY_BREAKING, pair_step_energy(i, j, a.n, load_pair_n2(idx).n, a.twist));
            // No longer a partner: a candidate again (it may touch again before a rebuild).
            insert_candidate(i, j);
            let last = base + count - 1u;
            store_pair_n1(idx, load_pair_n1(last));
            store_pair_n2(idx, load_pair_n2(last));
            pair_partner[idx] = pair_partner[last];
            count -= 1u;
        } else {
            slot += 1u;
        }
    }
    let wall_base = i * params.wall_slots;
    var wcount = wall_count[i];
    slot = 0u;
    while slot < wcount {
        let idx = wall_base + slot;
        let w = wall_table[wall_id[idx]];
        let delta = wall_overlap_at(i, w.point.xyz, w.point_lo.xyz, w.normal.xyz);
        if delta < -w.k.delta_c {
            let a = wall_n1[idx];
            add_tally(i, TALLY_WALLS, wall_step_energy(i, w, a.n, wall_anchor[idx], a.twist));
            let last = wall_base + wcount - 1u;
            wall_n1[idx] = wall_n1[last];
            wall_anchor[idx] = wall_anchor[last];
            wall_id[idx] = wall_id[last];
            wcount -= 1u;
        } else {
            slot += 1u;
        }
    }

    // Form pair contacts from the candidate list, partners in increasing index; a candidate
    // that becomes a partner leaves the list (kept in order, compacted in place).
    let list = i * NEIGHBOUR_CAPACITY;
    let candidates = neighbour_count[i];
    var kept = 0u;
    for (var k = 0u; k < candidates; k++) {
        let j = neighbour_list[list + k];
        let centres = pair_centres(i, j);
        let d = centres.x1 - centres.x2;
        let distance = vec_length(d);
        let full = count >= params.pair_slots;
        if 2.0lf * r - distance < 0.0lf || has_pair(i, count, j) || full {
            if full && !(2.0lf * r - distance < 0.0lf) {
                flag(FLAG_PAIR_SLOTS, i);
            }
            neighbour_list[list + kept] = j;
            kept += 1u;
            continue;
        }
        let nc = d / distance;
        let n1 = -nc;
        let n2 = nc;
        add_tally(i, TALLY_FORMING, -pair_step_energy(i, j, n1, n2, 0.0lf));
        let idx = base + count;
        store_pair_n1(idx, contact_pointer(n1, 0.0lf));
        store_pair_n2(idx, second_pointer(n2));
        pair_partner[idx] = j;
        count += 1u;
    }
    neighbour_count[i] = kept;
    pair_count[i] = count;

    // Form wall contacts, in wall order.
    for (var w_idx = 0u; w_idx < params.wall_count; w_idx++) {
        // Only the plane for the test: the whole Wall (224 bytes) only where a contact forms.
        let normal = walls[w_idx].normal.xyz;
        if wall_overlap_at(i, walls[w_idx].point.xyz, walls[w_idx].point_lo.xyz, normal) < 0.0lf
            || has_wall(i, wcount, w_idx) {
            continue;
        }
        let w = walls[w_idx];
        if wcount >= params.wall_slots {
            flag(FLAG_WALL_SLOTS, i);
            break;
        }
        let n1 = -normal;
        let frame = wall_frame(i, w);
        let anchor = anchor_out_of_frame(frame.x - normal * r, frame);
        add_tally(i, TALLY_WALLS, -wall_step_energy(i, w, n1, anchor, 0.0lf));
        let idx = wall_base + wcount;
        wall_n1[idx] = contact_pointer(n1, 0.0lf);
        wall_anchor[idx] = anchor;
        wall_id[idx] = w_idx;
        wcount += 1u;
    }
    wall_count[i] = wcount;
}

// Contacts present at the start are part of the initial state, not a dissipation
// (CpuEngine::new resets the tally after its first contacts pass).
@compute @workgroup_size(MONOMER_GROUP)
fn contacts_clear_tally(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    for (var c = 0u; c < TALLY_STRIDE; c++) {
        tally[i * TALLY_STRIDE + c] = tally_entry(0.0lf);
    }
}

// The tests of contacts_scan for every listed pair contact, on the state as it is: after an
// upload, where no integrate_pairs ran since the bits were cleared (backend::gpu::engine::upload).
@compute @workgroup_size(PAIR_GROUP)
fn contacts_pair_tests(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * PAIR_GROUP;
    let length = work_length(WORK_PAIRS);
    for (var k = id.x; k < length; k += stride) {
        let idx = contact_list[k];
        if pair_slot_in_use(idx) {
            let i = idx / params.pair_slots;
            let stored_n1 = load_pair_n1(idx);
            let centres = pair_centres(i, pair_partner[idx]);
            test_pair_contact(
                i, centres.x1, centres.x2,
                stored_n1.n, load_pair_n2(idx).n, stored_n1.twist,
            );
        }
    }
}
