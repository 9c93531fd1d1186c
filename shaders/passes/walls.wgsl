// requires: bindings owner interaction wall twisting math
//
// Monomer–wall force pass, twin of wall_forces in src/backend/cpu/passes/walls.rs: the contacts pass
// evaluates the wall contacts of the monomers that have any (wall_contacts_of in
// engine/owner.wgsl), and wall_forces gathers per monomer the forces pass's per-contact results
// then the wall contacts' results, then does the step's work bookkeeping (the trapezoid sums
// of wall_forces and reduce_walls_final in src/backend/cpu/passes/walls.rs, its twins); its first
// invocations also sum the wall forces per block
// (reduce_walls, whose twin is in src/state/reduction.rs).
//
// Gather order equals the CPU's: a monomer's force starts at zero, takes −F of every contact it
// is the partner of in increasing owner index (the CPU visits owners in index order), then +F
// of its own slots in slot order, then its wall contacts in slot order. Same operands, same
// order: the same bits.
//
// Bookkeeping: the CPU sums 0.5 (F_d(n) + F_d(n+1))·v dt over monomers and
// 0.5 (F_w(n) + F_w(n+1))·v_w dt over walls each step. Here each monomer keeps its share (its
// wall contacts' Σ_w F_w·v_w dt from the previous step in `aux`) in its own cumulative tally,
// summed over monomers only when the diagnostics block is read: same terms, another order.

@compute @workgroup_size(MONOMER_GROUP)
fn wall_forces(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    // The per-block wall-force sums ride along (a dispatch of their own costs lavapipe more
    // than the sums): they read only what the contacts pass wrote.
    if i < (params.n + REDUCE_BLOCK - 1u) / REDUCE_BLOCK {
        reduce_walls(i);
    }
    if i >= params.n {
        return;
    }
    // Gather pair contacts: incoming slots sorted by owner (slot ids sort as their owners do).
    var list: array<u32, INCOMING_CAPACITY>;
    let arrived = min(atomicLoad(&incoming_count[i]), INCOMING_CAPACITY);
    for (var a = 0u; a < arrived; a++) {
        let value = incoming[i * INCOMING_CAPACITY + a];
        var b = a;
        while b > 0u && list[b - 1u] > value {
            list[b] = list[b - 1u];
            b -= 1u;
        }
        list[b] = value;
    }
    atomicStore(&incoming_count[i], 0u);
    var f = vec3<f64>(0.0lf);
    var fd = vec3<f64>(0.0lf);
    var m = vec3<f64>(0.0lf);
    for (var a = 0u; a < arrived; a++) {
        let idx = list[a];
        let r = load_pair_result(idx);
        f = f - r.f;
        fd = fd - r.fd;
        m = m + r.m2;
    }
    for (var slot = 0u; slot < pair_count[i]; slot++) {
        let idx = i * params.pair_slots + slot;
        let r = load_pair_result(idx);
        f = f + r.f;
        fd = fd + r.fd;
        m = m + r.m1;
    }

    // Wall contacts, as wall_contacts_of found them, in slot order.
    let v = velocity[i].xyz;
    var power = 0.0lf;
    var damping_power = 0.0lf;
    for (var slot = 0u; slot < wall_count[i]; slot++) {
        let idx = i * params.wall_slots + slot;
        let wf = wall_force[idx].xyz;
        let wd = wall_damping[idx].xyz;
        f = f + wf;
        fd = fd + wd;
        m = m + wall_torque[idx].xyz;
        let travel = wall_table[wall_id[idx]].velocity.xyz * params.dt;
        power = power + vec_dot(wf, travel);
        damping_power = damping_power + vec_dot(wd, travel);
    }

    // Work over the step by the trapezoid rule (wall_forces in src/backend/cpu/passes/walls.rs).
    let s = aux[i];
    let fd_before = damping_force[i].xyz;
    add_tally(i, TALLY_DAMPING, -(0.5lf * vec_dot(fd_before + fd, v * params.dt)));
    add_tally(i, TALLY_DAMPING, 0.5lf * (s.damping_power + damping_power));
    add_tally(i, TALLY_WALL_WORK, 0.5lf * (s.wall_power + power));
    aux[i] = MonomerAux(s.inverse_mass_scale, s.inverse_inertia_scale, power, damping_power);
    force[i] = vec4<f64>(f, 0.0lf);
    torque[i] = vec4<f64>(m, 0.0lf);
    damping_force[i] = vec4<f64>(fd, 0.0lf);
}

// wall_contacts_of (engine/owner.wgsl) for the monomers contacts_scan listed with
// OWNER_WALLS, without their contact events: the step runs it in the contacts pass
// (contacts.wgsl), after the events; this entry point lets the forces be tested on a state
// whose events have not run. Each invocation takes every stride-th entry, as a dispatch holds
// at most work_groups_max groups.
@compute @workgroup_size(WORK_GROUP)
fn wall_contacts(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * WORK_GROUP;
    let length = work_length(WORK_CONTACTS);
    for (var k = id.x; k < length; k += stride) {
        let item = work_item(WORK_CONTACTS, k);
        if (item & OWNER_WALLS) != 0u {
            wall_contacts_of(item & OWNER_INDEX);
        }
    }
}

// First stage of the per-wall force sums (reduce.wgsl): the wall contacts of REDUCE_BLOCK
// consecutive monomers, in index and slot order, per wall.
fn reduce_walls(block: u32) {
    let first = block * REDUCE_BLOCK;
    var sums: array<vec3<f64>, MAX_WALLS>;
    for (var w = 0u; w < MAX_WALLS; w++) {
        sums[w] = vec3<f64>(0.0lf);
    }
    let end = min(first + REDUCE_BLOCK, params.n);
    for (var i = first; i < end; i++) {
        for (var slot = 0u; slot < wall_count[i]; slot++) {
            let idx = i * params.wall_slots + slot;
            let wall = wall_id[idx];
            let f = wall_force[idx].xyz;
            // Loops of constant length, which the compiler unrolls, so `sums` is indexed by
            // constants and lives in registers (at a per-lane index it would be memory).
            for (var w = 0u; w < MAX_WALLS; w++) {
                if w == wall {
                    sums[w] = sums[w] + f;
                }
            }
        }
    }
    for (var w = 0u; w < MAX_WALLS; w++) {
        if w < params.wall_count {
            partials[block * MAX_WALLS + w] = vec4<f64>(sums[w], 0.0lf);
        }
    }
}
