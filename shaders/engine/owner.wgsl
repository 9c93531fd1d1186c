// requires: bindings positions interaction rolling sliding twisting wall math
//
// The work of one owner that the contacts pass does after the owner's contact events (and that
// forces_corrections and wall_contacts do alone in tests): the inelastic corrections of its
// pair contacts, and the limits and forces of its wall contacts. Each touches only the owner's
// slots and tally, so one invocation per owner does all of it, in the CPU's order.

// The inelastic corrections of owner `i`'s contacts: twin of apply_inelastic_limits in
// src/backend/cpu/law/corrections_lanes.rs.
fn apply_inelastic_limits(i: u32) {
    let k = params.pair;
    let r = params.radius;
    for (var slot = 0u; slot < pair_count[i]; slot++) {
        let idx = i * params.pair_slots + slot;
        let j = pair_partner[idx];
        let centres = pair_centres(i, j);
        let x1 = centres.x1;
        let x2 = centres.x2;
        // The records as stored (engine/pointers.wgsl): the corrections work on them.
        var p1 = load_pair_n1(idx);
        var p2 = load_pair_n2(idx);

        let nc = vec_normalize(x1 - x2);
        // The tangential step energy of the contact as it stands (a correction changes no
        // other part): a correction's "after" is the next one's "before" (`current` in the
        // CPU twin).
        var current = 0.0lf;
        var known = false;
        let rolled = rolling_correction_of(p1, p2, k.reduced_radius, k.xi_crit);
        if rolled.changed {
            let before = pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist);
            p1 = rolled.p1;
            p2 = rolled.p2;
            current = pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist);
            known = true;
            add_tally(i, TALLY_ROLLING, before - current);
        }
        let slid = sliding_correction_of(p1, p2, nc, r, k.zeta_crit);
        if slid.changed {
            var before = current;
            if !known {
                before = pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist);
            }
            p1 = slid.p1;
            p2 = slid.p2;
            current = pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist);
            known = true;
            add_tally(i, TALLY_SLIDING, before - current);
        }
        let twisted = twisting_correction(p1.twist, k.phi_crit);
        if twisted.changed {
            var before = current;
            if !known {
                before = pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist);
            }
            p1 = with_twist(p1, twisted.twist);
            add_tally(i, TALLY_TWISTING, before - pair_tangential_step_energy(i, j, p1.n, p2.n, p1.twist));
        }
        store_pair_n1(idx, p1);
        store_pair_n2(idx, p2);
    }
}


// The wall contacts of monomer `i`: inelastic limits (apply_wall_inelastic_limits in
// src/backend/cpu/law/walls.rs), then forces, stored per slot for wall_forces. Few monomers touch a wall,
// and lavapipe would run this for every monomer of a SIMD group in which one does; hence a list.
fn wall_contacts_of(i: u32) {
    let r = params.radius;
    let v = velocity[i].xyz;
    for (var slot = 0u; slot < wall_count[i]; slot++) {
        let idx = i * params.wall_slots + slot;
        let wall = wall_table[wall_id[idx]];
        let k = wall.k;
        let normal = wall.normal.xyz;
        let stored = wall_n1[idx];
        var n1 = stored.n;
        var twist = stored.twist;
        // Positions and anchors in the wall's frame (engine/positions.wgsl): the box's in the
        // exact precision.
        let frame = wall_frame(i, wall);
        let x = frame.x;
        var anchor = anchor_into_frame(wall_anchor[idx], frame);

        // apply_wall_inelastic_limits: everything goes to the walls channel. The contact as it
        // was, for its step energy should a correction change it.
        let n1_before = n1;
        let anchor_before = anchor;
        let twist_before = twist;
        var changed = false;
        let rolled = wall_rolling_correction_of(stored, anchor, normal, r, k.xi_crit);
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
            let kept = anchor_out_of_frame(anchor, frame);
            // The tangential step energy: a correction changes no other part of it.
            let before = wall_tangential_step_energy(i, wall, n1_before, anchor_out_of_frame(anchor_before, frame), twist_before);
            add_tally(i, TALLY_WALLS, before - wall_tangential_step_energy(i, wall, n1, kept, twist));
            wall_n1[idx] = replaced_contact_pointer(stored, n1, twist);
            wall_anchor[idx] = kept;
        }

        let it = wall_interaction(frame, v, n1, anchor, twist);
        wall_force[idx] = vec4<f64>(it.f, 0.0lf);
        wall_damping[idx] = vec4<f64>(it.fd, 0.0lf);
        wall_torque[idx] = vec4<f64>(it.m, 0.0lf);
    }
}

