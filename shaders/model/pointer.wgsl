// requires: math
//
// Contact pointers: unit vectors fixed in their monomer, turned by its rotation.
// Twin of src/model/pointer.rs.

// Turns `n` by the rotation vector `w` (axis w/|w|, angle |w|) and renormalises. sin and cos are
// the Rust twin's Taylor polynomials (to θ¹¹ and θ¹⁰): the f64 transcendental builtins are
// unreliable on some drivers (lavapipe's f64 sin returns garbage).
fn rotate_pointer(n: vec3<f64>, w: vec3<f64>) -> vec3<f64> {
    let t2 = vec_length_squared(w);
    if t2 == 0.0lf {
        return n;
    }
    // sin(θ)/θ and (1 − cos θ)/θ² as polynomials in θ².
    let sinc = 1.0lf - t2 / 6.0lf
        * (1.0lf - t2 / 20.0lf * (1.0lf - t2 / 42.0lf * (1.0lf - t2 / 72.0lf * (1.0lf - t2 / 110.0lf))));
    let cosc = 0.5lf
        * (1.0lf - t2 / 12.0lf * (1.0lf - t2 / 30.0lf * (1.0lf - t2 / 56.0lf * (1.0lf - t2 / 90.0lf))));
    let cos_theta = 1.0lf - t2 * cosc;
    let rotated = n * cos_theta + vec_cross(w, n) * sinc + w * (vec_dot(w, n) * cosc);
    return vec_normalize(rotated);
}
