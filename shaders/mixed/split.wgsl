// requires: double_f32 math32
//
// Split positions: voxel index (i32) + f32 offset (+ its low part). Twin of
// src/mixed/split.rs (`SplitPosition::advance` is `split_position_advance`, `Separation::between` is
// `separation_between`, `Separation::vector` is `separation_vector`).

// 2⁻²⁰ cm.
const VOXEL: f32 = 9.5367431640625e-7f;

struct SplitPosition {
    voxel: vec3<i32>,
    offset: vec3<f32>,
    offset_lo: vec3<f32>,
}

struct Separation {
    coarse: vec3<f32>,
    fine: vec3<f32>,
}

// Moves by dx and carries whole voxels from the offset to the index, each axis a double-f32.
fn split_position_advance(p: SplitPosition, dx: vec3<f32>) -> SplitPosition {
    var out = p;
    for (var axis = 0u; axis < 3u; axis++) {
        let sum = double_f32_add_f32(DoubleF32(p.offset[axis], p.offset_lo[axis]), dx[axis]);
        let carry = floor(sum.hi / VOXEL);
        let kept = two_sum(sum.hi, -carry * VOXEL);
        let r = two_sum(kept.x, kept.y + sum.lo);
        out.voxel[axis] = p.voxel[axis] + i32(carry);
        out.offset[axis] = r.x;
        out.offset_lo[axis] = r.y;
    }
    return out;
}

fn separation_between(a: SplitPosition, b: SplitPosition) -> Separation {
    let k = b.voxel - a.voxel;
    return Separation(vec3<f32>(k) * VOXEL, b.offset - a.offset);
}

fn separation_vector(s: Separation) -> vec3<f32> {
    return s.coarse + s.fine;
}

// Overlap 2R − |r| from (|r|² − (2R)²) = (Σc² − (2R)²) + Σ(2c + f)·f.
fn pair_overlap(s: Separation, two_r: f32, two_r_squared: DoubleF32) -> f32 {
    let c = s.coarse;
    let f = s.fine;
    let head = (vec32_dot(c, c) - two_r_squared.hi) - two_r_squared.lo;
    let tail = vec32_dot(2.0f * c + f, f);
    let excess = head + tail;
    let distance = vec32_length(separation_vector(s));
    return -excess / (distance + two_r);
}
