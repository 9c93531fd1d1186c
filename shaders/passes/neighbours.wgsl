// requires: bindings positions cells math
//
// Neighbour passes, twin of src/backend/cpu/passes/neighbours.rs: candidate lists (Verlet lists) of the pairs
// within 2r + skin that are not in contact (the CPU's lists keep those too), rebuilt only when some monomer has moved more than half the skin since the
// last build (integrate_drift raises FLAG_REBUILD and sizes their indirect dispatches);
// otherwise they are dispatched with no workgroups.
// Any pair that can touch before the next rebuild is in the lists, so the contacts pass forms
// the same contacts as the CPU whatever the rebuild schedule.
//
// neighbours inserts every monomer into the bucket of its cell (edge 2r + skin),
// neighbours_list scans the 27 cells around each monomer; contacts_scan empties the buckets
// again (a pass over the whole table every step cost more than the rest of a quiet step). A full
// bucket or list is flagged (FLAG_BUCKET, FLAG_NEIGHBOURS, with the monomer concerned), never
// silently dropped.

fn rebuild_due() -> bool {
    return atomicLoad(&flags[FLAG_REBUILD]) != NO_MONOMER;
}

@compute @workgroup_size(MONOMER_GROUP)
fn neighbours(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n || !rebuild_due() {
        return;
    }
    let b = bucket_of(cell_of(centre(i)));
    let at = atomicAdd(&bucket_count[b], 1u);
    if at < params.bucket_capacity {
        bucket_items[b * params.bucket_capacity + at] = i;
    } else {
        flag(FLAG_BUCKET, i);
    }
}

@compute @workgroup_size(MONOMER_GROUP)
fn neighbours_list(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n || !rebuild_due() {
        return;
    }
    let x = centre(i);
    let c = cell_of(x);
    let base = i * NEIGHBOUR_CAPACITY;
    var count = 0u;
    for (var dx = -1; dx <= 1; dx++) {
        for (var dy = -1; dy <= 1; dy++) {
            for (var dz = -1; dz <= 1; dz++) {
                let b = bucket_of(c + vec3<i32>(dx, dy, dz));
                let in_bucket = min(atomicLoad(&bucket_count[b]), params.bucket_capacity);
                for (var k = 0u; k < in_bucket; k++) {
                    let j = bucket_items[b * params.bucket_capacity + k];
                    let centres = pair_centres(i, j);
                    if j <= i || vec_length(centres.x1 - centres.x2) > params.cell
                        || has_pair(i, pair_count[i], j) {
                        continue;
                    }
                    // Insert in ascending order; cells sharing a bucket can offer j twice.
                    var at = count;
                    while at > 0u && neighbour_list[base + at - 1u] > j {
                        at -= 1u;
                    }
                    if at > 0u && neighbour_list[base + at - 1u] == j {
                        continue;
                    }
                    if count >= NEIGHBOUR_CAPACITY {
                        flag(FLAG_NEIGHBOURS, i);
                        continue;
                    }
                    for (var s = count; s > at; s--) {
                        neighbour_list[base + s] = neighbour_list[base + s - 1u];
                    }
                    neighbour_list[base + at] = j;
                    count += 1u;
                }
            }
        }
    }
    neighbour_count[i] = count;
    reference_position[i] = vec4<f64>(x, 0.0lf);
}
