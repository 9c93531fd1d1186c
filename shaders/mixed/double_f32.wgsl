// Double-f32 numbers: hi + lo with |lo| ≤ ulp(hi)/2. Twin of src/mixed/double_f32.rs
// (`DoubleF32::add_f32` is `double_f32_add_f32` here, and so on). Only f32 + and −, in the
// twin's order; the float operations must not be reassociated (the exact float mode marks
// them NoContraction, which Mesa also reads as "exact").

struct DoubleF32 {
    hi: f32,
    lo: f32,
}

// Knuth's TwoSum: (a + b rounded, its rounding error), exactly.
fn two_sum(a: f32, b: f32) -> vec2<f32> {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    let b_error = b - b_virtual;
    let a_error = a - a_virtual;
    return vec2<f32>(s, a_error + b_error);
}

// Dekker's FastTwoSum, for |a| ≥ |b| or a = 0.
fn fast_two_sum(a: f32, b: f32) -> vec2<f32> {
    let s = a + b;
    return vec2<f32>(s, b - (s - a));
}

fn double_f32_add_f32(x: DoubleF32, v: f32) -> DoubleF32 {
    let s = two_sum(x.hi, v);
    let r = fast_two_sum(s.x, s.y + x.lo);
    return DoubleF32(r.x, r.y);
}

fn double_f32_add_double(x: DoubleF32, y: DoubleF32) -> DoubleF32 {
    let s = two_sum(x.hi, y.hi);
    let r = fast_two_sum(s.x, s.y + (x.lo + y.lo));
    return DoubleF32(r.x, r.y);
}

fn double_f32_to_f32(x: DoubleF32) -> f32 {
    return x.hi + x.lo;
}
