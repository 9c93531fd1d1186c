// requires: bindings cells
//
// Neighbour pass, counterpart of src/cpu/neighbours.rs. The CPU keeps a Verlet list with a skin;
// the device rebuilds its cell table every step instead (two cheap dispatches, no list to keep
// valid): neighbours_clear empties the buckets, neighbours inserts every monomer into the bucket
// of its cell. The contacts pass then searches the 27 cells around each owner. Either way every
// pair within the contact distance 2r is a candidate, so both sides form the same contacts.
//
// Cells have edge `params.cell` ≥ 2r. A bucket holds `bucket_capacity` ids; a fuller one is
// flagged (FLAG_BUCKET, with the monomer that did not fit), never silently dropped.

@compute @workgroup_size(64)
fn neighbours_clear(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x <= params.table_mask {
        atomicStore(&bucket_count[id.x], 0u);
    }
}

@compute @workgroup_size(64)
fn neighbours(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    let b = bucket_of(cell_of(position[i].xyz));
    let at = atomicAdd(&bucket_count[b], 1u);
    if at < params.bucket_capacity {
        bucket_items[b * params.bucket_capacity + at] = i;
    } else {
        flag(FLAG_BUCKET, i);
    }
}
