// Vector helpers written out in glam's DVec3 operation order.
//
// The contact law's Rust side is written with glam, whose dot, cross, length and normalize fix
// the order of every rounding. The WGSL builtins leave that order (and the use of fused
// multiply-add or a reciprocal square root) to the driver, so the twins use these helpers
// instead: same operations, same order, same last bit. Their Rust twins are glam's methods,
// named in each comment; `model/` has no file for this module.

// DVec3::dot: (x·x') + (y·y') + (z·z'), summed left to right.
fn vec_dot(a: vec3<f64>, b: vec3<f64>) -> f64 {
    return (a.x * b.x) + (a.y * b.y) + (a.z * b.z);
}

// DVec3::length_squared.
fn vec_length_squared(a: vec3<f64>) -> f64 {
    return vec_dot(a, a);
}

// DVec3::length: a correctly rounded sqrt of the glam dot product.
fn vec_length(a: vec3<f64>) -> f64 {
    return sqrt(vec_dot(a, a));
}

// DVec3::cross.
fn vec_cross(a: vec3<f64>, b: vec3<f64>) -> vec3<f64> {
    return vec3<f64>(
        a.y * b.z - b.y * a.z,
        a.z * b.x - b.z * a.x,
        a.x * b.y - b.x * a.y,
    );
}

// DVec3::normalize: multiplies by 1/|a| (not a / |a|, nor inverseSqrt).
fn vec_normalize(a: vec3<f64>) -> vec3<f64> {
    return a * (1.0lf / vec_length(a));
}

// f64::signum without its NaN case: −0 gives −1 as in Rust. WGSL cannot bitcast an f64, so the
// sign of a zero is read from the sign of the infinity 1/v (IEEE division, as the drivers that
// offer f64 implement it).
fn signum_nonnan(v: f64) -> f64 {
    let negative = v < 0.0lf || (v == 0.0lf && 1.0lf / v < 0.0lf);
    return select(1.0lf, -1.0lf, negative);
}

// DVec3::any_orthonormal_vector (Duff et al. 2017, "Building an orthonormal basis, revisited"),
// for a unit vector `a`.
fn any_orthonormal_vector(a: vec3<f64>) -> vec3<f64> {
    let sign = signum_nonnan(a.z);
    let k = -1.0lf / (sign + a.z);
    let b = a.x * a.y * k;
    return vec3<f64>(b, sign + a.y * a.y * k, -a.y);
}
