// requires: bindings positions wall_sums interaction pointer twisting math
//
// Leap-frog pass, twin of src/backend/cpu/passes/integrate.rs: kick v(n−½) → v(n+½) with the forces at n, turn
// contact pointers and advance twist integrals with the mid-step angular velocities, drift
// positions and walls.
//
// The CPU does this in three loops over the monomers, and the contact loop reads the partner's
// kicked velocity and its position before the drift. On the device the loops are three entry
// points (three dispatches), because a dispatch boundary is the only barrier between
// invocations: integrate_kick (with the wall contacts' pointers, which need only the monomer's
// own spin), integrate_pairs (pair pointers and twist, per contact), integrate_drift.
// integrate_start is the half-step shift of the initial velocities (CpuEngine::new).

@compute @workgroup_size(MONOMER_GROUP)
fn integrate_kick(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    kick(i);
}

// The last step's wall sums (reduce_walls_final: invocation w for wall w), then the kick: what
// the step script runs inside a submission, a dispatch fewer per step (each costs lavapipe
// tens of µs). A submission's last step ends with reduce_walls_final itself, so the small
// block read between submissions is complete.
@compute @workgroup_size(MONOMER_GROUP)
fn integrate_kick_with_wall_sums(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i < MAX_WALLS {
        sum_wall_blocks(i);
    }
    if i >= params.n {
        return;
    }
    kick(i);
}

// Kick of monomer i, and its wall contacts' pointers and twist.
fn kick(i: u32) {
    let dt = params.dt;
    let s = aux[i];
    let v = velocity[i].xyz + force[i].xyz * (dt * params.inverse_mass * s.inverse_mass_scale);
    let w = angular_velocity[i].xyz
        + torque[i].xyz * (dt * params.inverse_inertia * s.inverse_inertia_scale);
    velocity[i] = vec4<f64>(v, 0.0lf);
    angular_velocity[i] = vec4<f64>(w, 0.0lf);
    // For this step's tests in integrate_pairs.
    atomicStore(&pair_tests[i], 0u);
    // Wall contacts need only the monomer's own mid-step spin.
    let turn = w * dt;
    for (var slot = 0u; slot < wall_count[i]; slot++) {
        let idx = i * params.wall_slots + slot;
        let a = wall_n1[idx];
        let normal = wall_table[wall_id[idx]].normal.xyz;
        wall_n1[idx] = turned_contact_pointer(a, turn, twist_increment(w, normal, dt));
    }
}

// One invocation per pair contact (the list contacts_scan built for the last contact
// events; each invocation takes every stride-th entry, as a dispatch holds at most
// work_groups_max groups).
@compute @workgroup_size(PAIR_GROUP)
fn integrate_pairs(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let stride = groups.x * PAIR_GROUP;
    let length = work_length(WORK_PAIRS);
    for (var k = id.x; k < length; k += stride) {
        let idx = contact_list[k];
        if pair_slot_in_use(idx) {
            turn_pair_pointers(idx);
        }
    }
}

// Turns both pointers of the pair contact in slot `idx` and advances its twist integral; then
// tests the contact for contacts_scan, at the positions integrate_drift is about to store
// (x + v dt, the drift's own expression: the same bits where the device does not fuse
// operations, FloatMode::Exact; where it may, a test at the threshold can differ by rounding
// and the event comes one step later).
fn turn_pair_pointers(idx: u32) {
    let dt = params.dt;
    let i = idx / params.pair_slots;
    let j = pair_partner[idx];
    let wi = angular_velocity[i].xyz;
    let wj = angular_velocity[j].xyz;
    let a = load_pair_n1(idx);
    let b = load_pair_n2(idx);
    let centres = pair_centres(i, j);
    let vi = velocity[i].xyz;
    let vj = velocity[j].xyz;
    // Contact normal at mid-step, x(n+½) = x(n) + v(n+½) dt/2.
    let nc_mid = vec_normalize((centres.x1 - centres.x2) + (vi - vj) * (0.5lf * dt));
    let twist_step = twist_increment(wi - wj, nc_mid, dt);
    let p1 = turned_contact_pointer(a, wi * dt, twist_step);
    let twist = p1.twist;
    let p2 = turned_second_pointer(b, wj * dt);
    let n1 = p1.n;
    let n2 = p2.n;
    store_pair_n1(idx, p1);
    store_pair_n2(idx, p2);
    test_pair_contact(i, centres.x1 + vi * params.dt, centres.x2 + vj * params.dt, n1, n2, twist);
}

@compute @workgroup_size(MONOMER_GROUP)
fn integrate_drift(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i < params.wall_count {
        drift_wall(i);
    }
    // Empty the work lists for this step's scan (a dispatch of its own would cost as much as
    // a small system's pass on lavapipe).
    if i < WORK_LISTS {
        atomicStore(&work[i], 0u);
        atomicStore(&work_args[3u * i], 0u);
        atomicStore(&work_args[3u * i + 1u], 1u);
        atomicStore(&work_args[3u * i + 2u], 1u);
    }
    if i >= params.n {
        return;
    }
    let x = drift_centre(i);
    // Not finite: |x| ≤ max is false for NaN and for ±∞.
    let v = velocity[i].xyz;
    let limit = 1.0e300lf;
    let finite = abs(x.x) <= limit && abs(x.y) <= limit && abs(x.z) <= limit
        && abs(v.x) <= limit && abs(v.y) <= limit && abs(v.z) <= limit;
    if !finite {
        flag(FLAG_NON_FINITE, i);
    }
    // Half the skin (cell − 2r) travelled since the candidate lists were built: rebuild them.
    let half_skin = 0.5lf * (params.cell - 2.0lf * params.radius);
    let moved = x - reference_position[i].xyz;
    if vec_dot(moved, moved) > half_skin * half_skin {
        flag(FLAG_REBUILD, i);
        atomicMax(&work_args[3u * ARGS_REBUILD], (params.n + MONOMER_GROUP - 1u) / MONOMER_GROUP);
    }
}

@compute @workgroup_size(MONOMER_GROUP)
fn integrate_start(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    let half = 0.5lf * params.dt;
    let s = aux[i];
    let v = velocity[i].xyz - force[i].xyz * (half * params.inverse_mass * s.inverse_mass_scale);
    let w = angular_velocity[i].xyz
        - torque[i].xyz * (half * params.inverse_inertia * s.inverse_inertia_scale);
    velocity[i] = vec4<f64>(v, 0.0lf);
    angular_velocity[i] = vec4<f64>(w, 0.0lf);
}

// After the initial force evaluation: the damping and wall-work channels book work over a step,
// and there is no step before time 0.
@compute @workgroup_size(MONOMER_GROUP)
fn integrate_clear_work(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    tally[i * TALLY_STRIDE + TALLY_DAMPING] = tally_entry(0.0lf);
    tally[i * TALLY_STRIDE + TALLY_WALL_WORK] = tally_entry(0.0lf);
}
