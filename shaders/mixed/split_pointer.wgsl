// requires: double_f32 math32
//
// Contact pointers as double-f32 vectors turned by f32 increments. Twin of
// src/mixed/split_pointer.rs.

struct SplitUnit {
    hi: vec3<f32>,
    lo: vec3<f32>,
}

fn rotate_split_pointer(n: SplitUnit, w: vec3<f32>) -> SplitUnit {
    let t2 = vec32_length_squared(w);
    if t2 == 0.0f {
        return n;
    }
    let sinc = 1.0f - t2 * (1.0f / 6.0f) * (1.0f - t2 * 0.05f * (1.0f - t2 * (1.0f / 42.0f)));
    let cosc = 0.5f * (1.0f - t2 * (1.0f / 12.0f) * (1.0f - t2 * (1.0f / 30.0f)));
    let h = n.hi;
    let delta = vec32_cross(w, h) * sinc + (w * vec32_dot(w, h) - h * t2) * cosc;
    var out = n;
    for (var axis = 0u; axis < 3u; axis++) {
        let sum = double_f32_add_f32(DoubleF32(n.hi[axis], n.lo[axis]), delta[axis]);
        out.hi[axis] = sum.hi;
        out.lo[axis] = sum.lo;
    }
    return out;
}
