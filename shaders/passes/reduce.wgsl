// requires: bindings wall_sums
//
// Reductions into the diagnostics block, all in a fixed order (no float atomics exist, and a
// fixed order makes every run give the same bits):
// - reduce_walls (every step, in the wall_forces dispatch, walls.wgsl): each of the first
//   ⌈n / REDUCE_BLOCK⌉ invocations sums the wall-contact forces of REDUCE_BLOCK consecutive
//   monomers per wall; reduce_walls_final adds the blocks in order: the total force each wall
//   exerts at the current step, and its running sum since the host last read it.
// - reduce_diagnostics (when the host reads the block): the per-monomer energy tallies and the
//   contact counts, by one workgroup: strided partial sums, then added in invocation order.

// Dispatched alone at the end of a submission; inside one, the next step's
// integrate_kick_with_wall_sums does it (integrate.wgsl).
@compute @workgroup_size(8)
fn reduce_walls_final(@builtin(global_invocation_id) id: vec3<u32>) {
    sum_wall_blocks(id.x);
}

var<workgroup> part_tally: array<array<f64, TALLY_STRIDE>, DIAG_THREADS>;
var<workgroup> part_pairs: array<u32, DIAG_THREADS>;
var<workgroup> part_walls: array<u32, DIAG_THREADS>;

@compute @workgroup_size(64)
fn reduce_diagnostics(@builtin(local_invocation_index) t: u32) {
    var sums: array<f64, TALLY_STRIDE>;
    for (var c = 0u; c < TALLY_STRIDE; c++) {
        sums[c] = 0.0lf;
    }
    var pairs = 0u;
    var wall_contacts = 0u;
    for (var i = t; i < params.n; i += DIAG_THREADS) {
        for (var c = 0u; c < TALLY_STRIDE; c++) {
            sums[c] = sums[c] + tally_value(tally[i * TALLY_STRIDE + c]);
        }
        pairs += pair_count[i];
        wall_contacts += wall_count[i];
    }
    part_tally[t] = sums;
    part_pairs[t] = pairs;
    part_walls[t] = wall_contacts;
    workgroupBarrier();
    if t == 0u {
        var total: array<f64, TALLY_STRIDE>;
        for (var c = 0u; c < TALLY_STRIDE; c++) {
            total[c] = 0.0lf;
        }
        var p = 0u;
        var q = 0u;
        for (var k = 0u; k < DIAG_THREADS; k++) {
            for (var c = 0u; c < TALLY_STRIDE; c++) {
                total[c] = total[c] + part_tally[k][c];
            }
            p += part_pairs[k];
            q += part_walls[k];
        }
        for (var c = 0u; c < TALLY_STRIDE; c++) {
            diag[DIAG_TALLY + c] = total[c];
        }
        diag[DIAG_PAIR_CONTACTS] = f64(p);
        diag[DIAG_WALL_CONTACTS] = f64(q);
    }
}
