// requires: bindings interaction wall twisting math
//
// Monomer–wall force pass, twin of wall_forces in src/cpu/walls.rs: wall_contacts evaluates the
// wall contacts of the monomers that have any (a work list), and wall_forces gathers per
// monomer the forces pass's per-contact results (pair_forces' sums on the CPU), then the wall
// contacts' results, then does the step's work bookkeeping (the trapezoid sums of
// CpuEngine::step).
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

    // Wall contacts, as wall_contacts found them, in slot order.
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

    // Work over the step by the trapezoid rule (CpuEngine::step).
    let s = aux[i];
    let fd_before = damping_force[i].xyz;
    add_tally(i, TALLY_DAMPING, -(0.5lf * vec_dot(fd_before + fd, v * params.dt)));
    add_tally(i, TALLY_DAMPING, 0.5lf * (s.w + damping_power));
    add_tally(i, TALLY_WALL_WORK, 0.5lf * (s.z + power));
    aux[i] = vec4<f64>(s.x, s.y, power, damping_power);
    force[i] = vec4<f64>(f, 0.0lf);
    torque[i] = vec4<f64>(m, 0.0lf);
    damping_force[i] = vec4<f64>(fd, 0.0lf);
}

// The wall contacts of the monomers contacts_scan and contact_events listed (dispatched
// indirectly over that list; each invocation takes every stride-th entry, as a dispatch holds
// at most work_groups_max groups): inelastic limits, then forces, stored per slot for
// wall_forces. Few monomers touch a wall, and lavapipe would run this for every monomer of a
// SIMD group in which one does.
@compute @workgroup_size(WORK_GROUP)
fn wall_contacts(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * WORK_GROUP;
    let length = work_length(WORK_WALLS);
    for (var k = id.x; k < length; k += stride) {
        wall_contacts_of(work_item(WORK_WALLS, k));
    }
}

fn wall_contacts_of(i: u32) {
    let r = params.radius;
    let x = position[i].xyz;
    let v = velocity[i].xyz;
    for (var slot = 0u; slot < wall_count[i]; slot++) {
        let idx = i * params.wall_slots + slot;
        let wall = wall_table[wall_id[idx]];
        let k = wall.k;
        let normal = wall.normal.xyz;
        var n1 = wall_n1[idx].xyz;
        var twist = wall_n1[idx].w;
        var anchor = wall_anchor[idx].xyz;

        // apply_wall_inelastic_limits: everything goes to the walls channel.
        let before = wall_step_energy(i, wall, n1, anchor, twist);
        var changed = false;
        let rolled = wall_rolling_correction(n1, anchor, normal, r, k.xi_crit);
        if rolled.changed {
            n1 = rolled.n1;
            anchor = rolled.anchor;
            changed = true;
        }
        let zeta = wall_sliding_displacement(x, n1, r, anchor, normal);
        let slid = wall_sliding_correction(anchor, zeta, k.zeta_crit);
        if slid.changed {
            anchor = slid.p;
            changed = true;
        }
        let twisted = twisting_correction(twist, k.phi_crit);
        if twisted.changed {
            twist = twisted.twist;
            changed = true;
        }
        if changed {
            add_tally(i, TALLY_WALLS, before - wall_step_energy(i, wall, n1, anchor, twist));
            wall_n1[idx] = vec4<f64>(n1, twist);
            wall_anchor[idx] = vec4<f64>(anchor, 0.0lf);
        }

        let it = wall_interaction(x, v, wall, n1, anchor, twist);
        wall_force[idx] = vec4<f64>(it.f, 0.0lf);
        wall_damping[idx] = vec4<f64>(it.fd, 0.0lf);
        wall_torque[idx] = vec4<f64>(it.m, 0.0lf);
    }
}
