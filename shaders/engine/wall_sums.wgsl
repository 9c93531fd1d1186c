// requires: bindings
//
// Second stage of the per-wall force sums (reduce.wgsl): wall `w`'s block sums, added in block
// order, are the total force the wall exerts at the current step, stored and added to its
// running sum since the host last read the small block; invocation 0 counts the step.

fn sum_wall_blocks(w: u32) {
    if w == 0u {
        diag[DIAG_STEPS] = diag[DIAG_STEPS] + 1.0lf;
    }
    if w >= params.wall_count {
        return;
    }
    let blocks = (params.n + REDUCE_BLOCK - 1u) / REDUCE_BLOCK;
    var sum = vec3<f64>(0.0lf);
    for (var b = 0u; b < blocks; b++) {
        sum = sum + partials[b * MAX_WALLS + w].xyz;
    }
    for (var c = 0u; c < 3u; c++) {
        diag[DIAG_WALL_FORCE + 4u * w + c] = sum[c];
        let at = DIAG_WALL_FORCE_SUM + 4u * w + c;
        diag[at] = diag[at] + sum[c];
    }
}
