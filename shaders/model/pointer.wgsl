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
    // sin(θ)/θ and (1 − cos θ)/θ² as polynomials in θ², with the reciprocals 1/6, 1/20, …
    // written out (the f64 nearest to each), as in the twin.
    let sinc = 1.0lf - t2 * 0.16666666666666666lf
        * (1.0lf - t2 * 0.05lf * (1.0lf - t2 * 0.023809523809523808lf
        * (1.0lf - t2 * 0.013888888888888888lf * (1.0lf - t2 * 0.00909090909090909lf))));
    let cosc = 0.5lf * (1.0lf - t2 * 0.08333333333333333lf * (1.0lf - t2 * 0.03333333333333333lf
        * (1.0lf - t2 * 0.017857142857142856lf * (1.0lf - t2 * 0.011111111111111112lf))));
    let cos_theta = 1.0lf - t2 * cosc;
    let rotated = n * cos_theta + vec_cross(w, n) * sinc + w * (vec_dot(w, n) * cosc);
    return vec_normalize(rotated);
}
