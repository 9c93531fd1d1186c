// requires: double_f32 split split_pointer math32
//
// Evaluates the mixed precision mode's representations (shaders/mixed/) on one input record
// per invocation, for the test that holds each to its Rust twin in src/mixed/
// (tests/gpu_mixed_probe.rs). Records are flat arrays of 32-bit words (f32 or i32 bits),
// read and written in sequence; each output record starts with the counts of words read and
// written.

struct Params {
    cases: u32,
    in_stride: u32,
    out_stride: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> inputs: array<u32>;
@group(0) @binding(2) var<storage, read_write> outputs: array<u32>;

var<private> in_at: u32;
var<private> out_at: u32;

fn take() -> f32 {
    let v = bitcast<f32>(inputs[in_at]);
    in_at += 1u;
    return v;
}

fn take3() -> vec3<f32> {
    let x = take();
    let y = take();
    let z = take();
    return vec3<f32>(x, y, z);
}

fn take_i3() -> vec3<i32> {
    let v = vec3<i32>(
        bitcast<i32>(inputs[in_at]),
        bitcast<i32>(inputs[in_at + 1u]),
        bitcast<i32>(inputs[in_at + 2u]),
    );
    in_at += 3u;
    return v;
}

fn take_split() -> SplitPosition {
    let voxel = take_i3();
    let offset = take3();
    let offset_lo = take3();
    return SplitPosition(voxel, offset, offset_lo);
}

fn put(v: f32) {
    outputs[out_at] = bitcast<u32>(v);
    out_at += 1u;
}

fn put3(v: vec3<f32>) {
    put(v.x);
    put(v.y);
    put(v.z);
}

fn put_split(p: SplitPosition) {
    for (var k = 0u; k < 3u; k++) {
        outputs[out_at + k] = bitcast<u32>(p.voxel[k]);
    }
    out_at += 3u;
    put3(p.offset);
    put3(p.offset_lo);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= params.cases {
        return;
    }
    let in_base = index * params.in_stride;
    let out_base = index * params.out_stride;
    in_at = in_base;
    out_at = out_base + 2u;

    let a = take_split();
    let b = take_split();
    let dx = take3();
    let two_r = take();
    let two_r_squared = DoubleF32(take(), take());
    put_split(split_position_advance(a, dx));
    let s = separation_between(a, b);
    put3(s.coarse);
    put3(s.fine);
    put(pair_overlap(s, two_r, two_r_squared));

    let n = SplitUnit(take3(), take3());
    let w = take3();
    let turned = rotate_split_pointer(n, w);
    put3(turned.hi);
    put3(turned.lo);

    let x = DoubleF32(take(), take());
    let y = DoubleF32(take(), take());
    let v = take();
    let one = double_f32_add_f32(x, v);
    put(one.hi);
    put(one.lo);
    let both = double_f32_add_double(x, y);
    put(both.hi);
    put(both.lo);
    put(double_f32_to_f32(x));
    let t = two_sum(x.hi, v);
    put(t.x);
    put(t.y);

    outputs[out_base] = in_at - in_base;
    outputs[out_base + 1u] = out_at - out_base - 2u;
}
