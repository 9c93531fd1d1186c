//! Contact pointers: unit vectors fixed in their monomer, turned by its rotation.

use glam::DVec3;

/// Turns `n` by the rotation vector `w` (axis w/|w|, angle |w|) and renormalises.
///
/// sin and cos come from their Taylor series (to θ¹¹ and θ¹⁰), exact to rounding for the angles
/// a stable step produces (|w| ≲ 0.3; a stable step turns by ≲ 0.01), because f64 transcendental builtins are unreliable on some
/// GPU drivers; the GPU twin uses the same polynomial.
pub fn rotate_pointer(n: DVec3, w: DVec3) -> DVec3 {
    let t2 = w.length_squared();
    if t2 == 0.0 {
        return n;
    }
    // sin(θ)/θ and (1 − cos θ)/θ² as polynomials in θ².
    let sinc = 1.0
        - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0 * (1.0 - t2 / 110.0))));
    let cosc = 0.5 * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0 * (1.0 - t2 / 90.0))));
    let cos = 1.0 - t2 * cosc;
    let rotated = n * cos + w.cross(n) * sinc + w * (w.dot(n) * cosc);
    rotated.normalize()
}
