// requires: bindings positions interaction normal wall math
//
// The row measures, twins of the functions of the same names in src/state/rows.rs: what a
// measurement row reads of the state, reduced on the device so that the host reads a few
// numbers instead of the state (ROW_* in bindings.wgsl say where each number is).
// - row_sums (one invocation per monomer, one workgroup per block of REDUCE_BLOCK monomers):
//   each monomer's kinetic, rotational, JKR and tangential energy (monomer_energy) and the
//   block's sums of them in index order, with the extent of the centres in x and y;
//   row_sums_final adds the blocks as reduce_diagnostics adds tallies.
// - row_profile (one invocation per (slab, block)): the volume of the block's monomers inside
//   the slab, added in index order; row_profile_final adds the blocks in order per slab.
// - row_raster (one invocation per monomer) ORs the pixels its disk covers into a bitmap;
//   row_area counts them (an integer sum: atomics give the same count in any order).
// No float atomics anywhere: every float sum has one fixed order, the twin's.

const PI_F64: f64 = 3.141592653589793lf;

// monomer_energy of src/state/rows.rs.
fn monomer_energy(i: u32) -> array<f64, 4> {
    var e = array<f64, 4>(0.0lf, 0.0lf, 0.0lf, 0.0lf);
    let mass = row_data[ROW_MASS];
    let inertia = row_data[ROW_INERTIA];
    let a = aux[i];
    if a.inverse_mass_scale > 0.0lf {
        let v = velocity[i].xyz + force[i].xyz * (0.5lf * params.dt / mass * a.inverse_mass_scale);
        e[0] = 0.5lf * mass * vec_length_squared(v);
    }
    if a.inverse_inertia_scale > 0.0lf {
        let w = angular_velocity[i].xyz
            + torque[i].xyz * (0.5lf * params.dt / inertia * a.inverse_inertia_scale);
        e[1] = 0.5lf * inertia * vec_length_squared(w);
    }
    let k = params.pair;
    let r = params.radius;
    for (var slot = 0u; slot < pair_count[i]; slot++) {
        let idx = i * params.pair_slots + slot;
        let centres = pair_centres(i, pair_partner[idx]);
        let n1 = load_pair_n1(idx);
        let total = pair_contact_potential(centres, n1.n, load_pair_n2(idx).n, n1.twist);
        let normal = jkr_potential_at_overlap(centres.delta / k.delta0, k.f_c, k.delta0);
        e[2] = e[2] + normal;
        e[3] = e[3] + (total - normal);
    }
    for (var slot = 0u; slot < wall_count[i]; slot++) {
        let idx = i * params.wall_slots + slot;
        let frame = wall_frame(i, wall_table[wall_id[idx]]);
        let wall = frame.wall;
        let n1 = wall_n1[idx];
        let anchor = anchor_into_frame(wall_anchor[idx], frame);
        let total = wall_contact_potential(frame, n1.n, anchor, n1.twist);
        let delta = frame.delta;
        let normal = jkr_potential_at_overlap(delta / wall.k.delta0, wall.k.f_c, wall.k.delta0);
        e[2] = e[2] + normal;
        e[3] = e[3] + (total - normal);
    }
    return e;
}

var<workgroup> row_part: array<array<f64, ROW_SUMS>, REDUCE_BLOCK>;

@compute @workgroup_size(REDUCE_BLOCK)
fn row_sums(
    @builtin(local_invocation_index) t: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let first = group.x * REDUCE_BLOCK;
    let i = first + t;
    if i < params.n {
        let e = monomer_energy(i);
        let p = centre(i);
        row_part[t] = array<f64, ROW_SUMS>(e[0], e[1], e[2], e[3], p.x, p.y, p.x, p.y);
    }
    workgroupBarrier();
    if t == 0u {
        let p = centre(first);
        var sums = array<f64, ROW_SUMS>(0.0lf, 0.0lf, 0.0lf, 0.0lf, p.x, p.y, p.x, p.y);
        let count = min(REDUCE_BLOCK, params.n - first);
        for (var k = 0u; k < count; k++) {
            for (var c = 0u; c < 4u; c++) {
                sums[c] = sums[c] + row_part[k][c];
            }
            sums[4] = min(sums[4], row_part[k][4]);
            sums[5] = min(sums[5], row_part[k][5]);
            sums[6] = max(sums[6], row_part[k][6]);
            sums[7] = max(sums[7], row_part[k][7]);
        }
        for (var c = 0u; c < ROW_SUMS; c++) {
            row_data[ROW_PARTIALS + group.x * ROW_SUMS + c] = sums[c];
        }
    }
}

fn row_empty() -> array<f64, ROW_SUMS> {
    // The twin's empty extent: ±f64::MAX, beyond any centre.
    let big = 1.7976931348623157e308lf;
    return array<f64, ROW_SUMS>(0.0lf, 0.0lf, 0.0lf, 0.0lf, big, big, -big, -big);
}

fn row_combine(into: array<f64, ROW_SUMS>, b: array<f64, ROW_SUMS>) -> array<f64, ROW_SUMS> {
    var out = into;
    for (var c = 0u; c < 4u; c++) {
        out[c] = out[c] + b[c];
    }
    out[4] = min(out[4], b[4]);
    out[5] = min(out[5], b[5]);
    out[6] = max(out[6], b[6]);
    out[7] = max(out[7], b[7]);
    return out;
}

@compute @workgroup_size(DIAG_THREADS)
fn row_sums_final(@builtin(local_invocation_index) t: u32) {
    let blocks = (params.n + REDUCE_BLOCK - 1u) / REDUCE_BLOCK;
    var part = row_empty();
    for (var b = t; b < blocks; b += DIAG_THREADS) {
        var block: array<f64, ROW_SUMS>;
        for (var c = 0u; c < ROW_SUMS; c++) {
            block[c] = row_data[ROW_PARTIALS + b * ROW_SUMS + c];
        }
        part = row_combine(part, block);
    }
    row_part[t] = part;
    workgroupBarrier();
    if t == 0u {
        var total = row_empty();
        for (var k = 0u; k < DIAG_THREADS; k++) {
            total = row_combine(total, row_part[k]);
        }
        for (var c = 0u; c < ROW_SUMS; c++) {
            row_data[ROW_RESULTS + c] = total[c];
        }
    }
}

// volume_below of src/state/rows.rs.
fn volume_below(r: f64, sphere: f64, t: f64) -> f64 {
    if t <= -r {
        return 0.0lf;
    }
    if t >= r {
        return sphere;
    }
    return PI_F64 * ((r + t) * (r + t)) * (2.0lf * r - t) / 3.0lf;
}

// slab_share of src/state/rows.rs.
fn slab_share(r: f64, sphere: f64, z: f64, k: u32) -> f64 {
    let thickness = row_data[ROW_SLAB_THICKNESS];
    let zc = z - row_data[ROW_SLAB_BOTTOM];
    let first = max(floor((zc - r) / thickness), 0.0lf);
    let last = min(max(floor((zc + r) / thickness), 0.0lf), row_data[ROW_SLABS] - 1.0lf);
    let kf = f64(k);
    if kf < first || kf > last {
        return 0.0lf;
    }
    let lo = kf * thickness - zc;
    let hi = (kf + 1.0lf) * thickness - zc;
    return volume_below(r, sphere, hi) - volume_below(r, sphere, lo);
}

// Invocation g takes slab g / blocks and block g % blocks; a dispatch holds at most
// params.work_groups_max groups, so longer grids are walked with a stride.
@compute @workgroup_size(MONOMER_GROUP)
fn row_profile(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let blocks = (params.n + REDUCE_BLOCK - 1u) / REDUCE_BLOCK;
    let slabs = u32(row_data[ROW_SLABS]);
    let r = params.radius;
    let sphere = row_data[ROW_SPHERE];
    for (var g = id.x; g < slabs * blocks; g += groups.x * MONOMER_GROUP) {
        let k = g / blocks;
        let b = g - k * blocks;
        let end = min((b + 1u) * REDUCE_BLOCK, params.n);
        var sum = 0.0lf;
        for (var i = b * REDUCE_BLOCK; i < end; i++) {
            sum = sum + slab_share(r, sphere, centre(i).z, k);
        }
        row_profile_data[slabs + g] = sum;
    }
}

@compute @workgroup_size(MONOMER_GROUP)
fn row_profile_final(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x;
    let slabs = u32(row_data[ROW_SLABS]);
    if k >= slabs {
        return;
    }
    let blocks = (params.n + REDUCE_BLOCK - 1u) / REDUCE_BLOCK;
    var sum = 0.0lf;
    for (var b = 0u; b < blocks; b++) {
        sum = sum + row_profile_data[slabs + k * blocks + b];
    }
    row_profile_data[k] = sum;
}

// Sets bits a..=b of the bitmap (after the count in row_bits[0]).
fn set_pixels(a: u32, b: u32) {
    for (var w = a / 32u; w <= b / 32u; w++) {
        let lo = max(a, w * 32u) - w * 32u;
        let hi = min(b, w * 32u + 31u) - w * 32u;
        // Bits lo..=hi; a shift by 32 is undefined, so the full word is spelled out.
        var mask = 0xffffffffu;
        if hi - lo < 31u {
            mask = ((1u << (hi - lo + 1u)) - 1u) << lo;
        }
        atomicOr(&row_bits[1u + w], mask);
    }
}

@compute @workgroup_size(MONOMER_GROUP)
fn row_raster(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.n {
        return;
    }
    let r = params.radius;
    let h = row_data[ROW_PIXEL];
    let x0 = row_data[ROW_X0];
    let y0 = row_data[ROW_Y0];
    let nx = row_data[ROW_NX];
    let ny = row_data[ROW_NY];
    let r2 = r * r;
    let p = centre(i);
    let iy0 = u32(max(floor((p.y - r - y0) / h), 0.0lf));
    let iy1 = u32(min(ceil((p.y + r - y0) / h), ny - 1.0lf));
    for (var iy = iy0; iy <= iy1; iy++) {
        let dy = y0 + (f64(iy) + 0.5lf) * h - p.y;
        let rest = r2 - dy * dy;
        if rest < 0.0lf {
            continue;
        }
        let half = sqrt(rest);
        let ix0 = max(ceil((p.x - half - x0) / h - 0.5lf), 0.0lf);
        let ix1 = min(max(floor((p.x + half - x0) / h - 0.5lf), 0.0lf), nx - 1.0lf);
        if ix0 <= ix1 {
            let row = iy * u32(nx);
            set_pixels(row + u32(ix0), row + u32(ix1));
        }
    }
}

var<workgroup> row_pixels: atomic<u32>;

@compute @workgroup_size(MONOMER_GROUP)
fn row_area(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let words = (u32(row_data[ROW_NX]) * u32(row_data[ROW_NY]) + 31u) / 32u;
    if t == 0u {
        atomicStore(&row_pixels, 0u);
    }
    workgroupBarrier();
    // A bitmap longer than the largest dispatch is walked with a stride.
    var mine = 0u;
    for (var w = id.x; w < words; w += groups.x * MONOMER_GROUP) {
        mine += countOneBits(atomicLoad(&row_bits[1u + w]));
    }
    atomicAdd(&row_pixels, mine);
    workgroupBarrier();
    if t == 0u {
        atomicAdd(&row_bits[0], atomicLoad(&row_pixels));
    }
}
