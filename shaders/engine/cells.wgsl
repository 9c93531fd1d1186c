// requires: bindings
//
// Binning cells for an unbounded domain: integer cell coordinates hashed into a fixed table of
// buckets. Distinct cells may share a bucket; that only adds candidates, which the distance test
// removes. Used by the neighbours pass (insert) and the contacts pass (search).

fn cell_of(x: vec3<f64>) -> vec3<i32> {
    return vec3<i32>(floor(x / params.cell));
}

fn bucket_of(c: vec3<i32>) -> u32 {
    let u = bitcast<vec3<u32>>(c);
    return ((u.x * 73856093u) ^ (u.y * 19349663u) ^ (u.z * 83492791u)) & params.table_mask;
}
